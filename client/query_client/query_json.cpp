#include "query_client/query_json.h"

#include <iomanip>
#include <sstream>

namespace ort::client {
namespace {

std::string quoted(const std::string& s) {
  std::ostringstream o;
  o << '"';
  for (char c : s) {
    if (c == '"' || c == '\\')
      o << '\\' << c;
    else if (static_cast<unsigned char>(c) < 0x20)
      o << "\\u" << std::hex << std::setw(4) << std::setfill('0') << int(c) << std::dec;
    else
      o << c;
  }
  return o.str() + '"';
}

template <class R>
void head(std::ostream& out, const R& r) {
  out << "{\"request_id\": " << r.request_id << ", \"snapshot_id\": " << r.snapshot_id
      << ", \"map_utime\": " << r.map_utime << ", \"status\": " << quoted(status_name(r.status))
      << ", \"error\": " << quoted(r.error);
}

}  // namespace

std::string json_quoted(const std::string& s) { return quoted(s); }

const char* state_name(int8_t occ) { return occ == 2 ? "occupied" : occ == 1 ? "free" : "unknown"; }
const char* status_name(int8_t s) {
  switch (s) {
    case 0: return "ok";
    case 1: return "bad request";
    case 2: return "not ready";
    case 3: return "busy";
    case 4: return "refused";
  }
  return "unknown status";
}

void write_points_json(std::ostream& out, const std::vector<float>& xyz, const octomap_rt::occupancy_reply_t& r) {
  out << std::setprecision(9);
  head(out, r);
  out << ", \"results\": [";
  for (int i = 0; i < r.num_results; ++i)
    out << (i ? ", " : "") << "{\"x\": " << xyz[3 * i] << ", \"y\": " << xyz[3 * i + 1] << ", \"z\": " << xyz[3 * i + 2]
        << ", \"state\": \"" << state_name(r.occupancy[i]) << "\", \"probability\": " << r.probability[i] << "}";
  out << "]}\n";
}

void write_rays_json(std::ostream& out, const octomap_rt::ray_reply_t& r) {
  out << std::setprecision(9);
  head(out, r);
  out << ", \"results\": [";
  for (int i = 0; i < r.num_rays; ++i)
    out << (i ? ", " : "") << "{\"hit\": " << (r.hit[i] ? "true" : "false") << ", \"end\": [" << r.end_xyz[3 * i]
        << ", " << r.end_xyz[3 * i + 1] << ", " << r.end_xyz[3 * i + 2] << "], \"end_state\": \""
        << state_name(r.end_state[i]) << "\"}";
  out << "]}\n";
}

void write_boxes_json(std::ostream& out, const octomap_rt::box_reply_t& r) {
  head(out, r);
  out << ", \"results\": [";
  for (int i = 0; i < r.num_boxes; ++i)
    out << (i ? ", " : "") << "{\"occupied\": " << r.occupied[i] << ", \"free\": " << r.free[i]
        << ", \"unknown\": " << r.unknown[i] << ", \"any_occupied\": " << (r.any_occupied[i] ? "true" : "false") << "}";
  out << "]}\n";
}

void write_region_json(std::ostream& out, const std::vector<octomap_rt::region_chunk_t>& chunks) {
  out << std::setprecision(9);
  head(out, chunks.front());
  out << ", \"resolution\": " << chunks.front().resolution << ", \"voxels\": [";
  bool first = true;
  for (const auto& c : chunks)
    for (int i = 0; i < c.num_voxels; ++i, first = false)
      out << (first ? "" : ", ") << "{\"center\": [" << c.center_xyz[3 * i] << ", " << c.center_xyz[3 * i + 1] << ", "
          << c.center_xyz[3 * i + 2] << "], \"depth\": " << int(c.depth[i]) << ", \"state\": \""
          << state_name(c.state[i]) << "\"}";
  out << "]}\n";
}

void write_grid_json(std::ostream& out, const Grid& g, const std::string& png_path) {
  out << std::setprecision(9);
  head(out, g.header);
  int counts[3] = {0, 0, 0};
  for (int8_t c : g.cells) counts[c >= 0 && c <= 2 ? c : 0]++;
  out << ", \"width\": " << g.header.width << ", \"height\": " << g.header.height
      << ", \"cell_size\": " << g.header.cell_size << ", \"origin\": [" << g.header.origin_x << ", "
      << g.header.origin_y << "], \"counts\": {\"unknown\": " << counts[0] << ", \"free\": " << counts[1]
      << ", \"occupied\": " << counts[2] << "}, \"cell_values\": {\"unknown\": 0, \"free\": 1, \"occupied\": 2}"
      << ", \"png\": " << quoted(png_path) << ", \"cells\": [";
  // The cells themselves, one row (+y) after another, each row from -x to +x.
  for (int j = 0; j < g.header.height; ++j) {
    out << (j ? ", [" : "[");
    for (int i = 0; i < g.header.width; ++i) out << (i ? "," : "") << int(g.cells[size_t(j) * g.header.width + i]);
    out << "]";
  }
  out << "]}\n";
}

void write_edit_json(std::ostream& out, const octomap_rt::map_edit_ack_t& a) {
  head(out, a);
  out << ", \"op\": " << int(a.op) << ", \"voxels\": " << a.voxels << "}\n";
}

}  // namespace ort::client
