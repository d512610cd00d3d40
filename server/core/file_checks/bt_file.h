// A .bt file (OctoMap's binary format: two bits a child, free, occupied or inner, no values)
// as the .ot file OctoMap's readBinary followed by the prior loader's value rule would make of
// it (issue 25), without building the tree: so a .bt prior goes through the memory bound's
// split (octree/map_file_split.h) like a .ot one and never stands whole in memory as a tree.
//
// The values: a leaf is `occupied` or `free` as its two bits say; an inner node below the root
// is `occupied` if any leaf under it is (readBinary sets it to its children's maximum), the
// root always `occupied` (readBinary leaves it at the clamping maximum).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace ort {

// `bt` is a whole .bt file that core/file_checks/octree_file_check.h accepted, its node data
// starting at `data_offset`. Returns the .ot file's bytes (header: the .bt's lines, the first
// as a .ot's). Throws std::runtime_error when the data is not one whole tree.
std::string ot_file_from_bt(std::string_view bt, size_t data_offset, float occupied, float free);

}  // namespace ort
