#include "octree/region_codec.h"

#include <cstring>
#include <string>

#include "octree/batched/node_access.h"
#include "octree/batched/node_count.h"
#include "octree/region_sweep.h"

namespace ort {
namespace {

constexpr char kMagic[4] = {'O', 'R', 'T', 'R'};
constexpr uint32_t kVersion = 1;
constexpr size_t kHeaderBytes = 4 + 4 + 8 + 4 + 8 + 8;
constexpr size_t kNodeBytes = 5;

uint64_t fnv1a(std::span<const uint8_t> b) {
  uint64_t h = 1469598103934665603ull;
  for (uint8_t c : b) h = (h ^ c) * 1099511628211ull;
  return h;
}

template <class T>
void put(std::vector<uint8_t>& out, T v) {
  uint8_t b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.insert(out.end(), b, b + sizeof(T));
}

template <class T>
T get(std::span<const uint8_t> in, size_t at) {
  T v;
  std::memcpy(&v, in.data() + at, sizeof(T));
  return v;
}

void encode_node(const octomap::OcTree& tree, const octomap::OcTreeNode* node, std::vector<uint8_t>& out,
                 uint64_t& count) {
  ++count;
  uint8_t bits = 0;
  if (tree.nodeHasChildren(node))
    for (unsigned i = 0; i < 8; ++i)
      if (tree.nodeChildExists(node, i)) bits = static_cast<uint8_t>(bits | (1u << i));
  const float value = node->getLogOdds();
  const size_t at = out.size();
  out.resize(at + kNodeBytes);
  std::memcpy(out.data() + at, &value, sizeof value);
  out[at + 4] = bits;
  for (unsigned i = 0; i < 8; ++i)
    if (bits & (1u << i)) encode_node(tree, tree.getNodeChild(node, i), out, count);
}

// Checks the body's shape (every child announced is there, nothing left over, no deeper than
// the finest level) without touching a tree.
bool body_shape_ok(std::span<const uint8_t> body, size_t& at, unsigned depth) {
  if (at + kNodeBytes > body.size()) return false;
  const uint8_t bits = body[at + 4];
  at += kNodeBytes;
  if (bits && depth >= 16) return false;
  for (unsigned i = 0; i < 8; ++i)
    if ((bits & (1u << i)) && !body_shape_ok(body, at, depth + 1)) return false;
  return true;
}

void build_children(octomap::OcTree& tree, octomap::OcTreeNode* node, std::span<const uint8_t> body, size_t& at) {
  const uint8_t bits = body[at + 4];
  at += kNodeBytes;
  for (unsigned i = 0; i < 8; ++i) {
    if (!(bits & (1u << i))) continue;
    octomap::OcTreeNode* child = tree.createNodeChild(node, i);
    child->setLogOdds(get<float>(body, at));
    build_children(tree, child, body, at);
  }
}

// Fills the header in front of `out`'s body (kHeaderBytes reserved at its start).
void write_header(std::vector<uint8_t>& out, RegionId id, unsigned depth, uint64_t count) {
  std::vector<uint8_t> header(kMagic, kMagic + 4);
  put(header, kVersion);
  put(header, uint64_t(id));
  put(header, uint32_t(depth));
  put(header, count);
  put(header, fnv1a(std::span<const uint8_t>(out).subspan(kHeaderBytes)));
  std::memcpy(out.data(), header.data(), kHeaderBytes);
}

}  // namespace

std::vector<uint8_t> encode_region(const octomap::OcTree& tree, const RegionGrid& grid, RegionId id) {
  const RegionNode r = find_region(tree, grid, id);
  if (r.node == nullptr || r.depth != grid.depth || !tree.nodeHasChildren(r.node))
    throw RegionCodecError("region " + std::to_string(id) + " has no subtree at depth " + std::to_string(grid.depth));
  std::vector<uint8_t> out(kHeaderBytes);
  uint64_t count = 0;
  encode_node(tree, r.node, out, count);
  write_header(out, id, grid.depth, count);
  return out;
}

std::vector<uint8_t> region_bytes_from_body(RegionId id, unsigned depth, std::span<const uint8_t> body) {
  if (body.empty() || body.size() % kNodeBytes != 0)
    throw RegionCodecError("region " + std::to_string(id) + ": a body of " + std::to_string(body.size()) +
                           " bytes is not whole nodes");
  std::vector<uint8_t> out(kHeaderBytes + body.size());
  std::memcpy(out.data() + kHeaderBytes, body.data(), body.size());
  write_header(out, id, depth, body.size() / kNodeBytes);
  return out;
}

RegionHeader read_region_header(std::span<const uint8_t> bytes) {
  if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, 4) != 0 || get<uint32_t>(bytes, 4) != kVersion)
    throw RegionCodecError("not a region (" + std::to_string(bytes.size()) + " bytes, no ORTR v1 header)");
  RegionHeader h;
  h.id = get<uint64_t>(bytes, 8);
  h.depth = get<uint32_t>(bytes, 16);
  h.nodes = get<uint64_t>(bytes, 20);
  if (h.depth < 1 || h.depth > 16 || h.nodes == 0 || h.nodes != (bytes.size() - kHeaderBytes) / kNodeBytes ||
      (bytes.size() - kHeaderBytes) % kNodeBytes != 0)
    throw RegionCodecError("region " + std::to_string(h.id) + ": header and size disagree (" +
                           std::to_string(bytes.size()) + " bytes)");
  return h;
}

bool region_bytes_intact(std::span<const uint8_t> bytes) {
  try {
    read_region_header(bytes);
  } catch (const RegionCodecError&) {
    return false;
  }
  return get<uint64_t>(bytes, 28) == fnv1a(bytes.subspan(kHeaderBytes));
}

uint64_t strip_region(octomap::OcTree& tree, const RegionGrid& grid, RegionId id) {
  const RegionNode r = find_region(tree, grid, id);
  if (r.node == nullptr || r.depth != grid.depth || !tree.nodeHasChildren(r.node)) return 0;
  const size_t before = tree.size();
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(r.node, i)) delete_subtree(tree, r.node, i);
  free_empty_child_array(r.node);
  return before - tree.size();
}

DetachedSubtree detach_region(octomap::OcTree& tree, const RegionGrid& grid, RegionId id, uint64_t nodes_below) {
  const RegionNode r = find_region(tree, grid, id);
  if (r.node == nullptr || r.depth != grid.depth || !tree.nodeHasChildren(r.node)) return {};
  octomap::AbstractOcTreeNode**& children = detail::ChildArrayAccess::of(*r.node);
  DetachedSubtree d{children, nodes_below};
  children = nullptr;
  add_to_node_count(tree, -static_cast<int64_t>(nodes_below));
  return d;
}

namespace {
void free_children(octomap::AbstractOcTreeNode** children) {
  for (unsigned i = 0; i < 8; ++i) {
    auto* child = static_cast<octomap::OcTreeNode*>(children[i]);
    if (child == nullptr) continue;
    octomap::AbstractOcTreeNode**& below = detail::ChildArrayAccess::of(*child);
    if (below != nullptr) free_children(below);
    below = nullptr;
    delete child;
  }
  delete[] children;
}
}  // namespace

void free_detached(DetachedSubtree& d) {
  if (d.children != nullptr) free_children(d.children);
  d = {};
}

namespace {
void size_below(const octomap::OcTreeNode* node, SubtreeSize& s) {
  auto* const* children = detail::ChildArrayAccess::of(const_cast<octomap::OcTreeNode&>(*node));
  if (children == nullptr) return;
  bool inner = false;
  for (unsigned i = 0; i < 8; ++i) {
    if (children[i] == nullptr) continue;
    inner = true;
    ++s.nodes_below;
    size_below(static_cast<const octomap::OcTreeNode*>(children[i]), s);
  }
  s.inner += inner;
}

void encode_below(octomap::AbstractOcTreeNode* const* children, std::vector<uint8_t>& out, uint64_t& count) {
  for (unsigned i = 0; i < 8; ++i) {
    auto* node = static_cast<octomap::OcTreeNode*>(children[i]);
    if (node == nullptr) continue;
    ++count;
    octomap::AbstractOcTreeNode** below = detail::ChildArrayAccess::of(*node);
    uint8_t bits = 0;
    if (below != nullptr)
      for (unsigned j = 0; j < 8; ++j)
        if (below[j] != nullptr) bits = static_cast<uint8_t>(bits | (1u << j));
    const float value = node->getLogOdds();
    put(out, value);
    out.push_back(bits);
    if (bits) encode_below(below, out, count);
  }
}
}  // namespace

SubtreeSize region_size(const octomap::OcTree& tree, const RegionGrid& grid, RegionId id) {
  SubtreeSize s;
  const RegionNode r = find_region(tree, grid, id);
  if (r.node == nullptr || r.depth != grid.depth) return s;
  size_below(r.node, s);
  return s;
}

std::vector<uint8_t> encode_detached(RegionId id, unsigned depth, float root_log_odds, const DetachedSubtree& d) {
  if (d.children == nullptr) throw RegionCodecError("region " + std::to_string(id) + ": nothing detached to encode");
  std::vector<uint8_t> out(kHeaderBytes);
  out.reserve(kHeaderBytes + (d.nodes + 1) * kNodeBytes);
  uint8_t bits = 0;
  for (unsigned i = 0; i < 8; ++i)
    if (d.children[i] != nullptr) bits = static_cast<uint8_t>(bits | (1u << i));
  put(out, root_log_odds);
  out.push_back(bits);
  uint64_t count = 1;
  encode_below(d.children, out, count);
  write_header(out, id, depth, count);
  return out;
}

void reattach_region(octomap::OcTree& tree, const RegionGrid& grid, RegionId id, DetachedSubtree& d) {
  const RegionNode r = find_region(tree, grid, id);
  if (r.node == nullptr || r.depth != grid.depth || tree.nodeHasChildren(r.node))
    throw RegionCodecError("region " + std::to_string(id) + " has no stand-in to put its nodes back under");
  octomap::AbstractOcTreeNode**& children = detail::ChildArrayAccess::of(*r.node);
  delete[] children;  // an empty array a deleteNodeChild may have left (none is expected)
  children = d.children;
  add_to_node_count(tree, static_cast<int64_t>(d.nodes));
  d = {};
}

void restore_region(octomap::OcTree& tree, const RegionGrid& grid, RegionId id, std::span<const uint8_t> bytes) {
  const RegionHeader h = read_region_header(bytes);
  if (h.id != id || h.depth != grid.depth)
    throw RegionCodecError("the bytes are region " + std::to_string(h.id) + " at depth " + std::to_string(h.depth) +
                           ", not " + std::to_string(id) + " at " + std::to_string(grid.depth));
  if (!region_bytes_intact(bytes)) throw RegionCodecError("region " + std::to_string(id) + ": checksum mismatch");
  const std::span<const uint8_t> body = bytes.subspan(kHeaderBytes);
  size_t at = 0;
  if (!body_shape_ok(body, at, grid.depth) || at != body.size())
    throw RegionCodecError("region " + std::to_string(id) + ": the subtree's shape is broken");
  const RegionNode r = find_region(tree, grid, id);
  if (r.node == nullptr || r.depth != grid.depth || tree.nodeHasChildren(r.node))
    throw RegionCodecError("region " + std::to_string(id) + " has no stand-in to restore into");
  at = 0;
  r.node->setLogOdds(get<float>(body, 0));
  build_children(tree, r.node, body, at);
}

}  // namespace ort
