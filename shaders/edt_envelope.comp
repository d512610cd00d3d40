// Distance transform, passes y and z: per line, d[x] = min_q (x - q)^2 + f[q] by the lower
// envelope of parabolas (Felzenszwalb-Huttenlocher) in integers, in place: the sites' values
// are kept in scratch, so the line is overwritten only after it was read. The same arithmetic
// as server/distance/squared_edt.cpp's envelope_1d, so both give the same integers.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "edt_lines.glsl"

layout(std430, binding = 0) buffer Squared { uint squared[]; };
layout(std430, binding = 1) buffer Sites { int site[]; };     // v: the envelope's sites
layout(std430, binding = 2) buffer Starts { int start[]; };   // z: where each site is lowest
layout(std430, binding = 3) buffer Values { uint value[]; };  // f[v]

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

void main() {
  const uint l = line_id();
  if (l >= lines) return;
  const uint base = line_base(l);
  const uint s0 = l * n;  // this line's scratch
  int k = -1;
  for (int q = 0; q < int(n); ++q) {
    const uint fq = squared[base + uint(q) * stride];
    if (fq == kNoObstacle) continue;
    const int hq = int(fq) + q * q;
    for (;;) {
      if (k < 0) {
        k = 0;
        site[s0] = q;
        start[s0] = 0;
        value[s0] = fq;
        break;
      }
      const int p = site[s0 + uint(k)];
      const int s = floor_div(hq - (int(value[s0 + uint(k)]) + p * p), 2 * (q - p));
      if (s < start[s0 + uint(k)]) {
        --k;
        continue;
      }
      if (s + 1 < int(n)) {
        ++k;
        site[s0 + uint(k)] = q;
        start[s0 + uint(k)] = s + 1;
        value[s0 + uint(k)] = fq;
      }
      break;
    }
  }
  if (k < 0) {
    for (uint x = 0u; x < n; ++x) squared[base + x * stride] = kNoObstacle;
    return;
  }
  int j = 0;
  for (int x = 0; x < int(n); ++x) {
    while (j < k && start[s0 + uint(j + 1)] <= x) ++j;
    const int dx = x - site[s0 + uint(j)];
    squared[base + uint(x) * stride] = uint(dx * dx) + value[s0 + uint(j)];
  }
}
