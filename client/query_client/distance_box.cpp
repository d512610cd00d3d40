#include "query_client/distance_box.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "protocol/limits.h"
#include "protocol/map_protocol.h"
#include "protocol/zstd_codec.h"

namespace ort::client {

float DistanceBox::distance(int i, int j, int k) const {
  const uint32_t sq = squared[index(i, j, k)];
  if (sq == 0xFFFFFFFFu) return float(header.max_distance);
  return float(std::min(std::sqrt(double(sq)) * header.cell_size, header.max_distance));
}

std::array<double, 3> DistanceBox::center(int i, int j, int k) const {
  const int idx[3] = {i, j, k};
  std::array<double, 3> c{};
  for (int a = 0; a < 3; ++a) c[a] = header.origin[a] + (idx[a] + 0.5) * header.cell_size;
  return c;
}

DistanceBox assemble_distance_box(const std::vector<octomap_rt::distance_box_chunk_t>& chunks) {
  if (chunks.empty()) throw DistanceBoxError("no chunk");
  DistanceBox b;
  b.header = chunks.front();
  b.header.data.clear();
  b.header.num_bytes = 0;
  if (b.header.status != 0) return b;
  const auto& h = b.header;
  for (int a = 0; a < 3; ++a)
    if (h.size[a] < 1) throw DistanceBoxError("a box axis has no cells");
  const size_t cells = size_t(h.size[0]) * h.size[1] * h.size[2];
  const size_t raw_size = cells * 4 * (h.with_gradient ? 4 : 1);
  if (h.uncompressed_size != int64_t(raw_size)) throw DistanceBoxError("uncompressed size disagrees with the box");
  if (h.total_size < 0 || h.total_size > int64_t(raw_size) + 65536) throw DistanceBoxError("implausible blob size");
  std::string blob(size_t(h.total_size), '\0');
  std::vector<bool> have(size_t(std::max(0, h.num_chunks)), false);
  for (const auto& c : chunks) {
    const size_t offset = size_t(c.chunk_index) * protocol::kChunkDataBytes;
    if (c.chunk_index < 0 || c.chunk_index >= h.num_chunks || offset + c.data.size() > blob.size())
      throw DistanceBoxError("chunk " + std::to_string(c.chunk_index) + " out of range");
    std::memcpy(blob.data() + offset, c.data.data(), c.data.size());
    have[size_t(c.chunk_index)] = true;
  }
  if (std::count(have.begin(), have.end(), false) > 0)
    throw DistanceBoxError(std::to_string(std::count(have.begin(), have.end(), false)) + " of " +
                           std::to_string(h.num_chunks) + " chunks missing");
  if (protocol::blob_hash(blob.data(), blob.size()) != h.blob_hash) throw DistanceBoxError("blob hash differs");
  const std::string raw = h.compression == h.COMPRESSION_ZSTD ? protocol::zstd_decompress(blob, raw_size) : blob;
  if (raw.size() != raw_size) throw DistanceBoxError("blob holds " + std::to_string(raw.size()) + " bytes");
  b.squared.resize(cells);
  std::memcpy(b.squared.data(), raw.data(), cells * 4);
  if (h.with_gradient) {
    b.gradient.resize(3 * cells);
    std::memcpy(b.gradient.data(), raw.data() + cells * 4, cells * 12);
  }
  return b;
}

}  // namespace ort::client
