#include "cli/query/distance_output.h"

#include <algorithm>
#include <cmath>
#include <iomanip>

#include "query_client/query_json.h"
#include "render/distance_slice.h"

namespace ort::client {
namespace {

template <class R>
void head(std::ostream& out, const R& r) {
  out << std::setprecision(9) << "{\"request_id\": " << r.request_id << ", \"map_epoch\": " << r.map_epoch
      << ", \"snapshot_id\": " << r.snapshot_id << ", \"map_utime\": " << r.map_utime
      << ", \"status\": " << json_quoted(status_name(r.status)) << ", \"error\": " << json_quoted(r.error)
      << ", \"max_distance\": " << r.max_distance;
}

}  // namespace

void write_distance_points_json(std::ostream& out, const std::vector<float>& xyz,
                                const octomap_rt::distance_points_reply_t& r) {
  head(out, r);
  out << ", \"cell_size\": " << r.cell_size << ", \"results\": [";
  for (int i = 0; i < r.num_points; ++i) {
    out << (i ? ", " : "") << "{\"x\": " << xyz[3 * i] << ", \"y\": " << xyz[3 * i + 1] << ", \"z\": " << xyz[3 * i + 2]
        << ", \"distance\": " << r.distance[i];
    if (r.num_gradient == 3 * r.num_points)
      out << ", \"gradient\": [" << r.gradient[3 * i] << ", " << r.gradient[3 * i + 1] << ", " << r.gradient[3 * i + 2]
          << "]";
    out << "}";
  }
  out << "]}\n";
}

void write_distance_path_json(std::ostream& out, const octomap_rt::distance_path_reply_t& r) {
  head(out, r);
  out << ", \"min_distance\": " << r.min_distance << ", \"min_xyz\": [" << r.min_xyz[0] << ", " << r.min_xyz[1] << ", "
      << r.min_xyz[2] << "], \"min_arc_length\": " << r.min_arc_length << ", \"min_sample\": " << r.min_sample
      << ", \"num_samples\": " << r.num_samples << "}\n";
}

void write_distance_box_json(std::ostream& out, const DistanceBox& b, const std::string& png) {
  const auto& h = b.header;
  head(out, h);
  out << ", \"cell_size\": " << h.cell_size << ", \"origin\": [" << h.origin[0] << ", " << h.origin[1] << ", "
      << h.origin[2] << "], \"size\": [" << h.size[0] << ", " << h.size[1] << ", " << h.size[2]
      << "], \"with_gradient\": " << (h.with_gradient ? "true" : "false") << ", \"chunks\": " << h.num_chunks
      << ", \"compressed_bytes\": " << h.total_size;
  if (h.status == 0 && !b.squared.empty()) {
    double lo = h.max_distance, sum = 0;
    int64_t obstacles = 0, clamped = 0;
    for (int k = 0; k < b.nz(); ++k)
      for (int j = 0; j < b.ny(); ++j)
        for (int i = 0; i < b.nx(); ++i) {
          const double d = b.distance(i, j, k);
          lo = std::min(lo, d), sum += d;
          obstacles += d == 0, clamped += b.squared[b.index(i, j, k)] == 0xFFFFFFFFu;
        }
    out << ", \"min_distance\": " << lo << ", \"mean_distance\": " << sum / double(b.squared.size())
        << ", \"obstacle_cells\": " << obstacles << ", \"clamped_cells\": " << clamped;
  }
  out << ", \"png\": " << json_quoted(png) << "}\n";
}

void write_distance_slice(const DistanceBox& b, double z, const std::string& path) {
  const auto& h = b.header;
  const int k = std::clamp(int(std::floor((z - h.origin[2]) / h.cell_size)), 0, b.nz() - 1);
  render::DistanceSlice s;
  s.width = b.nx(), s.height = b.ny();
  s.max_distance = h.max_distance, s.cell_size = h.cell_size;
  s.origin_x = h.origin[0], s.origin_y = h.origin[1], s.z = h.origin[2] + (k + 0.5) * h.cell_size;
  for (int j = 0; j < b.ny(); ++j)
    for (int i = 0; i < b.nx(); ++i) s.distance.push_back(b.distance(i, j, k));
  render::write_distance_slice_png(s, path);
}

}  // namespace ort::client
