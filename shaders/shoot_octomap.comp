// Ray shooting, `octomap` traversal: one invocation per ray. Free voxels exactly as
// OctoMap's computeRayKeys; the end voxel occupied when the ray's end is a measured hit.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "flush_denormals.glsl"

#include "ray_space.glsl"
#include "octomap_ray.glsl"

layout(local_size_x = 64) in;

void main() {
  const uint i = ray_base + gl_GlobalInvocationID.x;
  if (i >= ray_count) return;
  const RayEnd r = rays[i];
  if ((r.flags & kRayEndDropped) != 0u) return;  // a point GPU preparation dropped
  const vec3 origin = vec3(origin_x, origin_y, origin_z);
  const vec3 end = vec3(r.x, r.y, r.z);
  const ivec3 key_origin = ivec3(origin_key_x, origin_key_y, origin_key_z);
  const ivec3 key_end = coord_to_key(end);
  // Rays whose key box (plus the walk's possible overstep) misses this window mark nothing.
  if (!box_meets_window(min(key_origin, key_end) - 2, max(key_origin, key_end) + 2)) return;
  if ((r.flags & 1u) != 0u) mark_voxel(key_end, kStateOccupied);
  walk_octomap_ray(origin, key_origin, end, key_end);
}
