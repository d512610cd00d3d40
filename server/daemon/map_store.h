// The map on disk: loading a .ot at start (refusing another resolution) and atomic saves.
//
// A save never leaves a half-written map under the map's name: the bytes go to FILE.tmp,
// which is fsynced, renamed over FILE (rename is atomic on POSIX file systems), and then the
// directory is fsynced so the rename itself survives a power cut. A crash at any point leaves
// either the previous complete file or the new complete file.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include <octomap/OcTree.h>

namespace ort::daemon {

// OctoMap's full format (.ot: AbstractOcTree::write, with log-odds) in memory.
std::string serialize_map(const octomap::OcTree& tree);

// Reads a .ot file. Throws std::runtime_error when it is missing, unreadable, not an OcTree,
// or its resolution differs from `resolution` (the message names both).
std::unique_ptr<octomap::OcTree> load_map(const std::string& path, double resolution);

// Writes `bytes` to `path` atomically (see above). Throws std::runtime_error with errno text.
void write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace ort::daemon
