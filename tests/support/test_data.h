// Where the tests find the real data sets: $OCTOMAP_RT_DATA, else the build's default
// (../shared/data beside the checkout).
#pragma once

#include <string>

namespace ort::test {

std::string data_dir();
// Full path of a data file; fails the calling test (ADD_FAILURE) with a clear message when
// the file is missing, and returns "".
std::string data_file(const std::string& relative);

}  // namespace ort::test
