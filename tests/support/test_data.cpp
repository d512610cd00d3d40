#include "support/test_data.h"

#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

namespace ort::test {

std::string data_dir() {
  if (const char* env = std::getenv("OCTOMAP_RT_DATA"); env && *env) return env;
  return OCTOMAP_RT_DATA_DIR;
}

std::string data_file(const std::string& relative) {
  const std::string path = data_dir() + "/" + relative;
  if (!std::filesystem::exists(path)) {
    ADD_FAILURE() << "data file " << path << " is missing; set OCTOMAP_RT_DATA to the folder that holds "
                  << "3dtk_dat/ and octomap_share/";
    return "";
  }
  return path;
}

}  // namespace ort::test
