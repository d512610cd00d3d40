#include "distance/squared_edt.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "distance/parallel_lines.h"

namespace ort::distance {
namespace {

int64_t floor_div(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

void row_pass(const uint8_t* occ, int n, uint32_t* out) {
  constexpr int64_t kFar = int64_t(1) << 40;
  int64_t last = -kFar;
  for (int x = 0; x < n; ++x) {
    if (occ[x]) last = x;
    const int64_t d = x - last;
    out[x] = d >= kMaxGridAxis ? kNoObstacle : static_cast<uint32_t>(d * d);
  }
  last = kFar;
  for (int x = n - 1; x >= 0; --x) {
    if (occ[x]) last = x;
    const int64_t d = last - x;
    if (d < kMaxGridAxis) out[x] = std::min(out[x], static_cast<uint32_t>(d * d));
  }
}

void envelope_1d(const uint32_t* f, int n, uint32_t* d, int32_t* v, int32_t* z) {
  // v[0..k]: the sites of the lower envelope; site v[j] is lowest on [z[j], z[j+1]).
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kNoObstacle) continue;
    const int64_t fq = int64_t(f[q]) + int64_t(q) * q;
    for (;;) {
      if (k < 0) {
        k = 0, v[0] = q, z[0] = 0;
        break;
      }
      const int p = v[k];
      // q is strictly lower than p for x > s (floor), equal at x = s when exact.
      const int64_t s = floor_div(fq - (int64_t(f[p]) + int64_t(p) * p), 2 * int64_t(q - p));
      if (s < z[k]) {  // p is nowhere lowest any more
        --k;
        continue;
      }
      if (s + 1 < n) ++k, v[k] = q, z[k] = static_cast<int32_t>(s + 1);
      break;
    }
  }
  if (k < 0) {
    std::fill(d, d + n, kNoObstacle);
    return;
  }
  int j = 0;
  for (int x = 0; x < n; ++x) {
    while (j < k && z[j + 1] <= x) ++j;
    const int64_t dx = x - v[j];
    d[x] = static_cast<uint32_t>(dx * dx + f[v[j]]);
  }
}

void squared_edt(std::span<const uint8_t> occupied, GridDims g, std::span<uint32_t> out, int threads) {
  if (g.nx < 1 || g.ny < 1 || g.nz < 1 || g.nx > kMaxGridAxis || g.ny > kMaxGridAxis || g.nz > kMaxGridAxis)
    throw DistanceError("grid dimensions out of range");
  if (occupied.size() != size_t(g.cells()) || out.size() != size_t(g.cells()))
    throw std::logic_error("squared_edt: buffer sizes differ from the grid's");
  const int64_t nx = g.nx, ny = g.ny, nz = g.nz;
  parallel_lines(ny * nz, threads, [&](int64_t row) { row_pass(&occupied[row * nx], g.nx, &out[row * nx]); });
  // y and z: each worker gathers a line into its own scratch, transforms it, scatters it back.
  auto column_pass = [&](int n, int64_t lines, auto index_of) {
    parallel_lines(lines, threads, [&, n](int64_t line) {
      thread_local std::vector<uint32_t> f, d;
      thread_local std::vector<int32_t> v, z;
      f.resize(n), d.resize(n), v.resize(n), z.resize(n);
      for (int i = 0; i < n; ++i) f[i] = out[index_of(line, i)];
      envelope_1d(f.data(), n, d.data(), v.data(), z.data());
      for (int i = 0; i < n; ++i) out[index_of(line, i)] = d[i];
    });
  };
  // Lines along y, numbered x + nx * z; along z, numbered x + nx * y.
  column_pass(g.ny, nx * nz, [nx, ny](int64_t l, int i) { return size_t((l / nx * ny + i) * nx + l % nx); });
  column_pass(g.nz, nx * ny, [nx, ny](int64_t l, int i) { return size_t((int64_t(i) * ny * nx) + l); });
}

SquaredEdt cpu_edt(int threads) {
  return [threads](std::span<const uint8_t> occ, GridDims dims, std::span<uint32_t> out) {
    squared_edt(occ, dims, out, threads);
  };
}

}  // namespace ort::distance
