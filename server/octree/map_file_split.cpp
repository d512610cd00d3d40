#include "octree/map_file_split.h"

#include <stdexcept>
#include <vector>

#include <octomap/OcTree.h>

#include "octree/region_codec.h"

namespace ort {
namespace {

constexpr size_t kNodeBytes = 5;  // a float log-odds and a byte of child bits (OctoMap's .ot)
constexpr uint64_t kNodeMemory = sizeof(octomap::OcTreeNode);
constexpr uint64_t kChildArrayMemory = 8 * sizeof(octomap::OcTreeNode*);

struct Splitter {
  std::string_view data;
  const RegionGrid& grid;
  uint64_t keep_bytes;
  const RegionSink& spill;
  MapFileSplit& out;

  uint8_t bits_at(size_t at) const {
    if (at + kNodeBytes > data.size()) throw std::runtime_error("the map's node data ends inside a node");
    return static_cast<uint8_t>(data[at + 4]);
  }

  // The end of the subtree at `at`, with its nodes and inner nodes counted.
  size_t skip(size_t at, unsigned depth, uint64_t& nodes, uint64_t& inner) const {
    const uint8_t bits = bits_at(at);
    ++nodes;
    at += kNodeBytes;
    if (bits == 0) return at;
    if (depth >= 16) throw std::runtime_error("the map has a node below the 16th level");
    ++inner;
    for (unsigned i = 0; i < 8; ++i)
      if (bits & (1u << i)) at = skip(at, depth + 1, nodes, inner);
    return at;
  }

  void keep(size_t from, size_t to, uint64_t nodes, uint64_t inner) {
    out.kept.append(data.substr(from, to - from));
    out.kept_nodes += nodes;
    out.kept_memory += nodes * kNodeMemory + inner * kChildArrayMemory;
  }

  size_t visit(size_t at, unsigned depth, const octomap::OcTreeKey& min_key) {
    const uint8_t bits = bits_at(at);
    if (depth == grid.depth && bits != 0) {
      uint64_t nodes = 0, inner = 0;
      const size_t end = skip(at, depth, nodes, inner);
      if (out.kept_memory + nodes * kNodeMemory + inner * kChildArrayMemory <= keep_bytes) {
        keep(at, end, nodes, inner);
      } else {
        const auto* body = reinterpret_cast<const uint8_t*>(data.data()) + at;
        spill(region_of(grid, min_key),
              region_bytes_from_body(region_of(grid, min_key), depth, std::span<const uint8_t>(body, end - at)));
        out.kept.append(data.substr(at, 4));  // the stand-in: the region root's value, no children
        out.kept.push_back('\0');
        out.kept_nodes++;
        out.kept_memory += kNodeMemory;
        out.spilled_regions++;
        out.spilled_nodes += nodes - 1;
      }
      return end;
    }
    keep(at, at + kNodeBytes, 1, bits != 0);
    at += kNodeBytes;
    if (bits != 0 && depth >= 16) throw std::runtime_error("the map has a node below the 16th level");
    for (unsigned i = 0; i < 8; ++i)
      if (bits & (1u << i)) at = visit(at, depth + 1, detail::child_min_key(min_key, depth, i));
    return at;
  }
};

// The header up to its data line with its "size" line set to `nodes`.
std::string header_with_size(std::string_view header, uint64_t nodes) {
  std::string out;
  size_t at = 0;
  bool sized = false;
  while (at < header.size()) {
    size_t nl = header.find('\n', at);
    if (nl == std::string_view::npos) nl = header.size() - 1;
    const std::string_view line = header.substr(at, nl + 1 - at);
    if (!sized && line.substr(0, 5) == "size ") {
      out += "size " + std::to_string(nodes) + "\n";
      sized = true;
    } else {
      out.append(line);
    }
    at = nl + 1;
  }
  if (!sized) throw std::runtime_error("the map's header has no size line");
  return out;
}

}  // namespace

MapFileSplit split_map_file(std::string_view ot, size_t data_offset, const RegionGrid& grid, uint64_t keep_bytes,
                            const RegionSink& spill) {
  if (data_offset > ot.size()) throw std::runtime_error("the map's header runs past its end");
  MapFileSplit out;
  const std::string_view data = ot.substr(data_offset);
  out.kept.reserve(std::min<size_t>(data.size(), keep_bytes / kNodeMemory * kNodeBytes) + data_offset + 64);
  out.kept_memory = sizeof(octomap::OcTree);
  Splitter s{data, grid, keep_bytes, spill, out};
  if (!data.empty() && s.visit(0, 0, octomap::OcTreeKey(0, 0, 0)) != data.size())
    throw std::runtime_error("the map's node data goes on past its tree");
  out.kept.insert(0, header_with_size(ot.substr(0, data_offset), out.kept_nodes));
  return out;
}

}  // namespace ort
