// Compaction: one invocation per touched word of the window. Emits one VoxelUpdate
// (uvec2: x | y << 16, z | state << 16; server/core/voxel_update.h) per voxel with a
// state, occupied winning over free, and clears the word, so the grid is clean for the
// next window without a pass over it.
#version 450

layout(local_size_x = 256) in;

layout(std430, binding = 0) buffer Grid { uint grid[]; };
layout(std430, binding = 1) readonly buffer Touched { uint touched[]; };
layout(std430, binding = 2) buffer Counters {
  uint dispatch_x;
  uint dispatch_y;
  uint dispatch_z;
  uint touched_count;
  uint emitted_count;
  uint walk_overruns;
  uint words_compacted;
};
layout(std430, binding = 3) writeonly buffer Voxels { uvec2 voxels[]; };

layout(push_constant) uniform CompactParams {
  int win_lo_x, win_lo_y, win_lo_z;
  uint chunk_begin;   // first entry of the touched list this pass covers
  uint win_nx, win_ny, win_nz;
  uint chunk_words;   // entries this pass covers at most (the output holds 16 times that)
};

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= chunk_words) return;
  const uint t = chunk_begin + i;
  if (t >= touched_count) return;
  const uint word = touched[t];
  const uint bits = grid[word];
  grid[word] = 0u;
  atomicAdd(words_compacted, 1u);
  uint present = (bits | (bits >> 1)) & 0x55555555u;  // bit 2j set: voxel j has a state
  const uint n = uint(bitCount(present));
  if (n == 0u) return;
  uint slot = atomicAdd(emitted_count, n);
  while (present != 0u) {
    const int bit = findLSB(present);
    present &= present - 1u;
    const uint state = ((bits >> uint(bit)) & 1u) != 0u ? 1u : 2u;  // 11 resolves to occupied
    const uint index = word * 16u + uint(bit >> 1);
    const uint x = index % win_nx;
    const uint rest = index / win_nx;
    const uint y = rest % win_ny;
    const uint z = rest / win_ny;
    voxels[slot++] = uvec2((uint(win_lo_x) + x) | ((uint(win_lo_y) + y) << 16),
                           (uint(win_lo_z) + z) | (state << 16));
  }
}
