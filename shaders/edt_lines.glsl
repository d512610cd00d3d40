// Shared by the distance-transform passes (edt_rows.comp, edt_envelope.comp): which line of
// the grid an invocation owns, and where its cells are. Mirrors server/gpu/distance_transform.cpp.
layout(local_size_x = 64) in;

layout(push_constant) uniform LinePush {
  uint n;       // cells on the line
  uint lines;   // lines of this pass
  uint stride;  // between two cells of a line
  uint div;     // line l starts at (l / div) * mul + l % div
  uint mul;
};

const uint kNoObstacle = 0xFFFFFFFFu;
const int kMaxAxis = 8192;

uint line_id() { return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u; }
uint line_base(uint l) { return (l / div) * mul + l % div; }
