// Loading a map file for viewing: OctoMap's binary `.bt` or full `.ot` (with log-odds).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include <octomap/OcTree.h>

namespace ort::render {

// Why a map file could not be used: missing, unreadable, or not an OcTree.
class MapFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads FILE.bt (OcTree::readBinary) or FILE.ot (AbstractOcTree::read, must hold an OcTree).
std::unique_ptr<octomap::OcTree> load_map_file(const std::string& path);

}  // namespace ort::render
