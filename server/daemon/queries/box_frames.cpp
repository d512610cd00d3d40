#include "daemon/queries/box_frames.h"

#include <algorithm>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <vector>

#include "distance/parallel_lines.h"
#include "protocol/zstd_codec.h"

namespace ort::daemon {
namespace {

// Slab s's two parts: the squared distances (clamped: kNoObstacle beyond max_distance, as
// answer_box) and, when asked, the gradients; little-endian hosts only (x86-64, arm64).
void cut_slab(const distance::BoxRead& r, const distance::DistanceField& f, int64_t k0, int64_t k1, bool gradient,
              std::string& sq_bytes, std::string& grad_bytes) {
  const distance::GridDims d = r.cells.dims;
  const size_t cells = size_t((k1 - k0) * d.nx * d.ny);
  sq_bytes.resize(cells * 4);
  grad_bytes.resize(gradient ? cells * 12 : 0);
  const double max_sq = (f.max_distance / f.cell_size) * (f.max_distance / f.cell_size);
  size_t c = 0;
  for (int64_t k = k0; k < k1; ++k)
    for (int64_t j = 0; j < d.ny; ++j)
      for (int64_t i = 0; i < d.nx; ++i, ++c) {
        const uint32_t s = f.squared[size_t(f.index(i + r.pad, j + r.pad, k + r.pad))];
        const uint32_t v = double(s) > max_sq ? distance::kNoObstacle : s;
        std::memcpy(sq_bytes.data() + c * 4, &v, 4);
        if (!gradient) continue;
        const auto g = f.gradient(i + r.pad, j + r.pad, k + r.pad);
        std::memcpy(grad_bytes.data() + c * 12, g.data(), 12);
      }
}

}  // namespace

BoxBlob box_blob(const distance::BoxRead& r, const distance::DistanceField& f, bool gradient, int zstd_level,
                 int threads, const std::string& key, distance::KeptFrames* kept, int64_t slab_cells) {
  const distance::GridDims d = r.cells.dims;
  if (f.box.dims.nx != d.nx + 2 * r.pad || f.box.dims.ny != d.ny + 2 * r.pad || f.box.dims.nz != d.nz + 2 * r.pad)
    throw std::logic_error("box_blob: the field is not of the box's padded grid");
  const int64_t layer = int64_t(d.nx) * d.ny;
  const int64_t per =
      slab_cells > 0 ? std::max<int64_t>(1, slab_cells / std::max<int64_t>(1, layer)) : std::max(1, d.nz);  // layers
  if (slab_cells <= 0) threads = 1;
  const int64_t slabs = (d.nz + per - 1) / per;
  const int64_t parts = gradient ? 2 : 1;
  const size_t frames = size_t(slabs * parts);  // frame p * slabs + s: part p of slab s
  const bool compress = zstd_level != 0;
  const bool reuse = kept && compress && kept->key == key && kept->raw.size() == frames;
  std::vector<std::string> raw(frames), packed(frames);
  std::vector<uint8_t> taken(frames, 0);
  std::vector<std::exception_ptr> failed(static_cast<size_t>(slabs));
  distance::parallel_lines(
      slabs, threads,
      [&](int64_t s) {
        try {
          std::string parts_bytes[2];
          cut_slab(r, f, s * per, std::min<int64_t>(d.nz, (s + 1) * per), gradient, parts_bytes[0], parts_bytes[1]);
          for (int64_t p = 0; p < parts; ++p) {
            const size_t fr = size_t(p * slabs + s);
            raw[fr] = std::move(parts_bytes[p]);
            if (reuse && kept->raw[fr] == raw[fr]) {
              packed[fr] = kept->packed[fr];
              taken[fr] = 1;
            } else if (compress) {
              packed[fr] = protocol::zstd_compress(raw[fr], zstd_level);
            }
          }
        } catch (...) {
          failed[size_t(s)] = std::current_exception();
        }
      },
      1);
  for (const auto& e : failed)
    if (e) std::rethrow_exception(e);
  BoxBlob b;
  b.raw_size = layer * d.nz * 4 * (gradient ? 4 : 1);
  size_t total = 0;
  for (size_t fr = 0; fr < frames; ++fr) total += compress ? packed[fr].size() : raw[fr].size();
  b.bytes.reserve(total);
  for (size_t fr = 0; fr < frames; ++fr) b.bytes += compress ? packed[fr] : raw[fr];
  if (compress) {
    b.frames = int64_t(frames);
    b.frames_kept = std::count(taken.begin(), taken.end(), uint8_t(1));
    if (kept) {
      kept->key = key;
      kept->raw = std::move(raw);
      kept->packed = std::move(packed);
    }
  }
  return b;
}

}  // namespace ort::daemon
