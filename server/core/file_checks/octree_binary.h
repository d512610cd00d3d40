// OctoMap's .bt of a tree without touching the tree (beside the checks of OctoMap's files):
// the bytes OcTree::writeBinary would write, which first turns the tree to maximum
// likelihood and prunes it (and so changes the tree it is given). Every .bt octomap-rt
// writes (snapshots, the OCTOMAP viewer message, `octomap-rt build -o FILE.bt`) comes from
// here, so OctoMap's own round trip (test_io: readBinary, writeBinary, readBinary, ==)
// accepts it, while the map of record keeps its log-odds and its shape.
//
// How: one walk finds which nodes OcTree::prune() would collapse on the max-likelihood tree,
// level by level from the finest up, including its stop at the first level where it
// collapses nothing; a second walk writes OctoMap's two bits per child with those nodes
// written as leaves, into a buffer, behind OctoMap's header with the pruned node count.
#pragma once

#include <ostream>
#include <string>

#include <octomap/OcTree.h>

namespace ort {

// The whole .bt file (header and data).
std::string octomap_binary_bytes(const octomap::OcTree& tree);
// The same, written to `out`; false when the stream failed.
bool write_octomap_binary(const octomap::OcTree& tree, std::ostream& out);

}  // namespace ort
