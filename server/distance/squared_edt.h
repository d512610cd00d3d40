// The exact squared Euclidean distance transform of a dense grid on CPU threads: three
// separable 1-D passes (x: nearest obstacle in the row; y, z: the lower envelope of parabolas
// of Felzenszwalb and Huttenlocher, "Distance Transforms of Sampled Functions", 2012), all in
// integers (the envelope's breakpoints by floor division), so the result is exact.
#pragma once

#include <cstdint>
#include <span>

#include "distance/distance_types.h"

namespace ort::distance {

// out[i] = min over obstacle cells o of |i - o|^2 (cell units), kNoObstacle without any.
// `threads` >= 1 workers split each pass's rows; the result does not depend on it.
void squared_edt(std::span<const uint8_t> occupied, GridDims dims, std::span<uint32_t> out, int threads);

// The 1-D pass of x on one row of n cells: out[x] = squared distance to the row's nearest
// obstacle (kNoObstacle without one).
void row_pass(const uint8_t* occ, int n, uint32_t* out);

// The 1-D pass of y and z on one line of n values (kNoObstacle = no site): d[x] =
// min_q (x - q)^2 + f[q]. `v` and `z` are scratch of n ints each. f and d may not alias.
void envelope_1d(const uint32_t* f, int n, uint32_t* d, int32_t* v, int32_t* z);

// A SquaredEdt (distance_types.h) running squared_edt with `threads` workers.
SquaredEdt cpu_edt(int threads);

}  // namespace ort::distance
