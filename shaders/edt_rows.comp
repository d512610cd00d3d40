// Distance transform, pass x: per row, the squared distance to the nearest obstacle cell of
// the row (two sweeps), kNoObstacle where the row has none. One invocation per row.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "edt_lines.glsl"

layout(std430, binding = 0) readonly buffer Occupied { uint occupied[]; };  // bytes, 4 a word
layout(std430, binding = 1) buffer Squared { uint squared[]; };

bool obstacle(uint i) { return ((occupied[i >> 2] >> ((i & 3u) * 8u)) & 0xFFu) != 0u; }

void main() {
  const uint l = line_id();
  if (l >= lines) return;
  const uint base = line_base(l);
  int last = -(1 << 20);
  for (uint x = 0u; x < n; ++x) {
    const uint i = base + x * stride;
    if (obstacle(i)) last = int(x);
    const int d = int(x) - last;
    squared[i] = d >= kMaxAxis ? kNoObstacle : uint(d * d);
  }
  last = 1 << 20;
  for (int x = int(n) - 1; x >= 0; --x) {
    const uint i = base + uint(x) * stride;
    if (obstacle(i)) last = x;
    const int d = last - x;
    if (d < kMaxAxis) squared[i] = min(squared[i], uint(d * d));
  }
}
