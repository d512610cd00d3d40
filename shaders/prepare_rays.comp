// Scan preparation on the GPU (server/gpu/gpu_prepare.h): one invocation per sensor-frame
// point. The same steps as the CPU's (server/engine/map_frame.h + prepare_scan.cpp), with
// OctoMap's float arithmetic, so every ray end is the CPU's bit for bit:
//   Pose6D::transform (quaternion products, float), drop non-finite points, cut rays longer
//   than max range (Vector3::normalized, float), drop ends outside the key range and rays
//   too short to walk (prepare_scan.h's degenerate_ray). Map-frame coordinates below
//   kTinyCoordinate read as 0 first (the scan contract, prepare_scan.h): decided on the bits,
//   so a GPU that flushes fp32 subnormals to 0 reads them as the CPU does.
// Every product and sum is `precise` (no contraction, no reassociation). Where OctoMap
// divides floats, the division is done in double and rounded to float: NVIDIA's fp32
// division is not IEEE, double division rounded once more gives the IEEE float quotient.
// Ray i stays ray i; a dropped point leaves a ray flagged kRayEndDropped that the shooting
// passes skip. The key box and the counts are reduced per workgroup, then atomically.
#version 450
#extension GL_ARB_gpu_shader_fp64 : require
#extension GL_GOOGLE_include_directive : require
#include "flush_denormals.glsl"

layout(local_size_x = 64) in;

const uint kRayEndOccupied = 1u;
const uint kRayEndDropped = 2u;
const int kTreeMaxVal = 32768;

struct RayEnd {
  float x, y, z;
  uint flags;
};

layout(std430, binding = 0) readonly buffer Points { float points[]; };  // x, y, z a point
layout(std430, binding = 1) writeonly buffer Rays { RayEnd rays[]; };
layout(std430, binding = 2) buffer Result {
  uint key_lo[3];  // key box of the kept ends; lo starts at ~0u, hi at 0
  uint key_hi[3];
  uint nonfinite;
  uint out_of_range;
  uint cut_at_max_range;
  uint degenerate;  // prepare_scan.h's degenerate_ray: end key != origin key, nearer than min_ray_length
  uint read_as_zero;  // points with a coordinate below tiny_coordinate read as 0
};

layout(push_constant) uniform PrepareParams {
  double resolution_factor;  // 1.0 / resolution, as OctoMap keeps it
  float rot_u, rot_x, rot_y, rot_z;  // the pose's rotation (OctoMap's float quaternion)
  float trans_x, trans_y, trans_z;
  uint point_count;
  float origin_x, origin_y, origin_z;
  uint point_base;  // first point of this dispatch
  float norm_sq_limit;  // largest |p - origin|^2 (float) whose OctoMap norm is <= max range
  float max_range_f;    // (float)max_range, as computeUpdate scales the direction
  uint has_max_range;   // 0: no limit
  float zero;           // 0.0f, as a run-time value: the compiler may not fold 0 * x away
  float tiny_coordinate;  // prepare_scan.h's kTinyCoordinate
  float min_ray_length;   // prepare_scan.h's kMinRayLength
};

shared uint s_lo[3], s_hi[3], s_nonfinite, s_out_of_range, s_cut, s_degenerate, s_read_as_zero;

bool finite(float f) { return (floatBitsToUint(f) & 0x7f800000u) != 0x7f800000u; }
bool finite3(vec3 v) { return finite(v.x) && finite(v.y) && finite(v.z); }

// Quaternion::operator* of OctoMap 1.9.7 (src/math/Quaternion.cpp), term for term.
vec4 quat_mul(vec4 a, vec4 b) {  // (u, x, y, z)
  precise float u = a.x * b.x - a.y * b.y - a.z * b.z - a.w * b.w;
  precise float x = a.z * b.w - b.z * a.w + a.x * b.y + b.x * a.y;
  precise float y = a.w * b.y - b.w * a.y + a.x * b.z + b.x * a.z;
  precise float z = a.y * b.z - b.y * a.z + a.x * b.w + b.x * a.w;
  return vec4(u, x, y, z);
}

// Pose6D::transform: rot.rotate(v) + trans, with rotate(v) = (q * (0, v)) * q.inv().
vec3 transform(vec3 v) {
  const vec4 q = vec4(rot_u, rot_x, rot_y, rot_z);
  const vec4 q_inv = vec4(rot_u, -rot_x, -rot_y, -rot_z);
  const vec4 r = quat_mul(quat_mul(q, vec4(zero, v)), q_inv);
  precise vec3 p = r.yzw + vec3(trans_x, trans_y, trans_z);
  return p;
}

// A coordinate below tiny_coordinate in magnitude (+-0 included), decided on the bits (the order
// of non-negative floats is their bits' order), so a subnormal the device would flush is seen.
bool below_tiny(float f) { return (floatBitsToUint(f) & 0x7fffffffu) < floatBitsToUint(tiny_coordinate); }
bool tiny(float f) { return below_tiny(f) && (floatBitsToUint(f) & 0x7fffffffu) != 0u; }  // and not 0
bool tiny3(vec3 v) { return tiny(v.x) || tiny(v.y) || tiny(v.z); }
// prepare_scan.h's read_tiny_as_zero: +0 (the same bits as the CPU's, -0 included).
vec3 read_tiny_as_zero(vec3 v) {
  return vec3(below_tiny(v.x) ? 0.0 : v.x, below_tiny(v.y) ? 0.0 : v.y, below_tiny(v.z) ? 0.0 : v.z);
}

// OctoMap's coordToKeyChecked: floor(resolution_factor * coordinate) in double.
bool coord_to_key_checked(vec3 c, out uvec3 key) {
  for (int i = 0; i < 3; ++i) {
    precise double scaled = floor(resolution_factor * double(c[i]));
    if (!(scaled >= double(-kTreeMaxVal) && scaled < double(kTreeMaxVal))) return false;
    key[i] = uint(int(scaled) + kTreeMaxVal);
  }
  return true;
}

// computeUpdate's max-range rule. norm() <= max_range is decided on |d|^2 in float against a
// threshold the host found with OctoMap's own double sqrt (the test is monotone in |d|^2).
// A cut end is origin + d.normalized() * (float)max_range.
bool apply_max_range(inout vec3 end, vec3 origin) {
  precise vec3 d = end - origin;
  precise float norm_sq = d.x * d.x + d.y * d.y + d.z * d.z;
  if (has_max_range == 0u || norm_sq <= norm_sq_limit) return false;
  const float len = float(sqrt(double(norm_sq)));  // (float)sqrt(double): IEEE float sqrt
  const double dlen = double(len);
  precise vec3 dir = vec3(float(double(d.x) / dlen), float(double(d.y) / dlen), float(double(d.z) / dlen));
  precise vec3 cut = origin + dir * max_range_f;
  end = cut;
  return true;
}

// prepare_scan.h's degenerate_ray, given that the keys differ: the end nearer than
// min_ray_length to the origin along every axis (a difference the device flushes is below it too).
bool too_short_to_walk(vec3 end, vec3 origin) {
  precise vec3 d = end - origin;
  return abs(d.x) < min_ray_length && abs(d.y) < min_ray_length && abs(d.z) < min_ray_length;
}

void main() {
  const uint lid = gl_LocalInvocationID.x;
  if (lid == 0u) {
    for (int i = 0; i < 3; ++i) {
      s_lo[i] = ~0u;
      s_hi[i] = 0u;
    }
    s_nonfinite = 0u;
    s_out_of_range = 0u;
    s_cut = 0u;
    s_degenerate = 0u;
    s_read_as_zero = 0u;
  }
  barrier();

  const uint i = point_base + gl_GlobalInvocationID.x;
  if (i < point_count) {
    const vec3 v = vec3(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
    RayEnd ray = RayEnd(0.0, 0.0, 0.0, kRayEndDropped);
    vec3 end = transform(v);
    uvec3 key;
    if (!finite3(v) || !finite3(end)) {
      atomicAdd(s_nonfinite, 1u);
    } else {
      // As sent or in the map frame (prepare_scan.h's tiny_as_sent_only): a subnormal the
      // transform made, which this device may have flushed to 0 already, is counted as the CPU counts it.
      if (tiny3(end) || tiny3(v)) atomicAdd(s_read_as_zero, 1u);
      end = read_tiny_as_zero(end);
      const bool cut = apply_max_range(end, vec3(origin_x, origin_y, origin_z));
      if (cut) atomicAdd(s_cut, 1u);
      uvec3 origin_key;
      if (!coord_to_key_checked(end, key)) {
        atomicAdd(s_out_of_range, 1u);
      } else if (coord_to_key_checked(vec3(origin_x, origin_y, origin_z), origin_key) && key != origin_key &&
                 too_short_to_walk(end, vec3(origin_x, origin_y, origin_z))) {
        atomicAdd(s_degenerate, 1u);
      } else {
        ray = RayEnd(end.x, end.y, end.z, cut ? 0u : kRayEndOccupied);
        for (int k = 0; k < 3; ++k) {
          atomicMin(s_lo[k], key[k]);
          atomicMax(s_hi[k], key[k]);
        }
      }
    }
    rays[i] = ray;
  }
  barrier();

  if (lid == 0u) {
    for (int k = 0; k < 3; ++k) {
      if (s_lo[k] != ~0u) atomicMin(key_lo[k], s_lo[k]);
      atomicMax(key_hi[k], s_hi[k]);
    }
    if (s_nonfinite != 0u) atomicAdd(nonfinite, s_nonfinite);
    if (s_out_of_range != 0u) atomicAdd(out_of_range, s_out_of_range);
    if (s_cut != 0u) atomicAdd(cut_at_max_range, s_cut);
    if (s_degenerate != 0u) atomicAdd(degenerate, s_degenerate);
    if (s_read_as_zero != 0u) atomicAdd(read_as_zero, s_read_as_zero);
  }
}
