// The GPU ray space (server/gpu/gpu_ray_space.h) as the shooting shaders see it: the
// persistent grid of 2-bit voxel states (16 voxels a word; bit 0 occupied, bit 1 free,
// 11 = occupied wins), the list of words touched in this window, and the counters.
// Layouts: server/gpu/shader_interface.h.
#ifndef RAY_SPACE_GLSL
#define RAY_SPACE_GLSL

const uint kStateOccupied = 1u;
const uint kStateFree = 2u;
const int kTreeMaxVal = 32768;

struct RayEnd {
  float x, y, z;
  uint flags;  // bit 0: the end voxel is a measured hit; bit 1: dropped (skip the ray)
};
const uint kRayEndDropped = 2u;  // set only by GPU preparation (prepare_rays.comp)

layout(std430, binding = 0) readonly buffer Rays { RayEnd rays[]; };
layout(std430, binding = 1) buffer Grid { uint grid[]; };
layout(std430, binding = 2) buffer Touched { uint touched[]; };
layout(std430, binding = 3) buffer Counters {
  uint dispatch_x;  // VkDispatchIndirectCommand of the compact pass: ceil(listed / 256)
  uint dispatch_y;
  uint dispatch_z;
  uint touched_count;  // words listed so far in this window
  uint emitted_count;  // voxels the compact pass wrote
  uint walk_overruns;    // rays stopped by the step guard (must stay 0)
  uint words_compacted;  // touched words the compact passes read and cleared
};

layout(push_constant) uniform ShootParams {
  double resolution;
  double resolution_factor;  // 1.0 / resolution, as OctoMap keeps it
  float origin_x, origin_y, origin_z;
  uint ray_count;
  int win_lo_x, win_lo_y, win_lo_z;  // the window's lowest key
  uint first_chunk_words;            // words the indirect compact pass covers
  uint win_nx, win_ny, win_nz;       // the window's extent in voxels
  uint ray_base;                     // first ray of this dispatch
  int origin_key_x, origin_key_y, origin_key_z;
  uint pad1;
};

const uint kCompactGroup = 256u;  // compact_touched.comp's local_size_x

// Sets the 2-bit state of voxel `key` if it lies in the current window. The first ray to
// touch a word lists it, so compaction and clearing cost in proportion to what was touched.
void mark_voxel(ivec3 key, uint state) {
  const ivec3 l = key - ivec3(win_lo_x, win_lo_y, win_lo_z);
  if (l.x < 0 || l.y < 0 || l.z < 0 || uint(l.x) >= win_nx || uint(l.y) >= win_ny || uint(l.z) >= win_nz) return;
  const uint index = uint(l.x) + win_nx * (uint(l.y) + win_ny * uint(l.z));
  const uint word = index >> 4;
  const uint bits = state << ((index & 15u) * 2u);
  // Within a scan states only gain bits, so a plain read that already shows ours is final:
  // this spares the atomic on the crowded words around the sensor.
  if ((grid[word] & bits) == bits) return;
  if (atomicOr(grid[word], bits) == 0u) {
    const uint slot = atomicAdd(touched_count, 1u);
    touched[slot] = word;
    if ((slot % kCompactGroup) == 0u && slot < first_chunk_words) atomicAdd(dispatch_x, 1u);
  }
}

// Does the key box [lo, hi] (inclusive) overlap the current window?
bool box_meets_window(ivec3 lo, ivec3 hi) {
  const ivec3 wlo = ivec3(win_lo_x, win_lo_y, win_lo_z);
  const ivec3 whi = wlo + ivec3(win_nx, win_ny, win_nz) - 1;
  return all(lessThanEqual(lo, whi)) && all(greaterThanEqual(hi, wlo));
}

// OctoMap's coordToKey: int(floor(resolution_factor * coordinate)) + 32768, in double.
ivec3 coord_to_key(vec3 c) {
  const double f = resolution_factor;
  return ivec3(int(floor(f * double(c.x))), int(floor(f * double(c.y))), int(floor(f * double(c.z)))) + kTreeMaxVal;
}

#endif
