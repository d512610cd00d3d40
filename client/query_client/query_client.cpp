#include "query_client/query_client.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <thread>

#include "core/clock.h"
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/distance_query_t.hpp"
#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/ray_query_t.hpp"
#include "protocol/channels.h"
#include "protocol/edit_mac.h"
#include "protocol/ids.h"

namespace ort::client {
namespace {

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

QueryClient::QueryClient(const std::string& url, std::string client_id, std::chrono::milliseconds timeout,
                         const std::string& ns)
    : lcm_(std::make_unique<lcm::LCM>(url)),
      channels_(protocol::channels_in(ns)),
      client_id_(std::move(client_id)),
      timeout_(timeout) {
  if (!lcm_->good()) throw std::runtime_error("LCM could not start on '" + url + "'");
  if (std::string why = protocol::check_client_id(client_id_); !why.empty()) throw std::invalid_argument(why);
  reply_channel_ = channels_.query_reply_prefix + upper(client_id_);
  if (std::string why = protocol::check_channel_length(reply_channel_); !why.empty())
    throw std::invalid_argument("client id '" + client_id_ + "': " + why);
  // Request ids differ between runs of the same client id (stale replies are ignored).
  next_request_ = now_utime();
}

QueryClient::~QueryClient() = default;

template <class Request>
void QueryClient::address(Request& r, const WaitFor& w) {
  r.utime = now_utime();
  r.request_id = next_request_++;
  r.min_snapshot_id = w.min_snapshot_id;
  r.wait_seq = w.robot_id.empty() ? -1 : w.seq;
  r.wait_robot_id = w.robot_id.empty() ? "" : w.robot_id;
  r.wait_timeout_ms = w.timeout_ms;
  r.client_id = client_id_;
  r.reply_channel = reply_channel_;
}

template <class Reply, class Request, class Done>
std::vector<Reply> QueryClient::exchange(const std::string& channel, Request& request, Done&& done) {
  std::vector<Reply> replies;
  struct Sink {
    std::vector<Reply>* out;
    int64_t id;
    void on(const lcm::ReceiveBuffer* rb, const std::string&) {
      Reply r;
      try {
        if (r.decode(rb->data, 0, static_cast<int>(rb->data_size)) < 0) return;
      } catch (const std::exception&) {
        return;  // not ours or corrupt: ignored
      }
      if (r.request_id == id) out->push_back(std::move(r));
    }
  } sink{&replies, request.request_id};
  lcm::Subscription* sub = lcm_->subscribe(reply_channel_, &Sink::on, &sink);
  sub->setQueueCapacity(4096);
  lcm_->publish(channel, &request);
  const auto deadline = SteadyClock::now() + timeout_;
  // BUSY says "this may fit another turn" (a full per-client queue, or a region or grid cut by
  // the time bound under the map lock while mapping held the cores): ask again, backing off,
  // until the timeout; a fresh request id so a late reply to the first ask is not mixed in.
  auto backoff = std::chrono::milliseconds(20);
  for (;;) {
    while (!done(replies)) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - SteadyClock::now());
      if (left.count() <= 0) {
        lcm_->unsubscribe(sub);
        throw QueryTimeout("no complete reply on " + reply_channel_ + " within " + std::to_string(timeout_.count()) +
                           " ms (is octomap-rt-server running on this LCM URL?)");
      }
      lcm_->handleTimeout(static_cast<int>(std::min<int64_t>(left.count(), 100)));
    }
    if (replies.front().status != octomap_rt::occupancy_reply_t::REPLY_BUSY || SteadyClock::now() + backoff >= deadline)
      break;
    busy_retries_++;
    std::this_thread::sleep_for(backoff);
    backoff = std::min(backoff * 2, std::chrono::milliseconds(500));
    replies.clear();
    request.request_id = sink.id = next_request_++;
    lcm_->publish(channel, &request);
  }
  lcm_->unsubscribe(sub);
  return replies;
}

namespace {
// When an exchange is complete: one reply, or every chunk (or a refusal, which comes alone).
template <class Reply>
bool one(const std::vector<Reply>& r) {
  return !r.empty();
}
template <class Reply>
bool all_chunks(const std::vector<Reply>& r) {
  return !r.empty() && (r[0].status != 0 || static_cast<int>(r.size()) >= r[0].num_chunks);
}
}  // namespace

octomap_rt::occupancy_reply_t QueryClient::points(const std::vector<float>& xyz, int depth, const WaitFor& w) {
  octomap_rt::occupancy_query_t q{};
  address(q, w);
  q.depth = depth;
  q.xyz = xyz;
  q.num_xyz = static_cast<int32_t>(xyz.size());
  return exchange<octomap_rt::occupancy_reply_t>(channels_.query_points, q, one<octomap_rt::occupancy_reply_t>).front();
}

octomap_rt::ray_reply_t QueryClient::rays(const std::vector<float>& origins, const std::vector<float>& directions,
                                          float max_range, bool ignore_unknown, const WaitFor& w) {
  octomap_rt::ray_query_t q{};
  address(q, w);
  q.ignore_unknown = ignore_unknown;
  q.max_range = max_range;
  q.origin_xyz = origins;
  q.direction_xyz = directions;
  q.num_xyz = static_cast<int32_t>(origins.size());
  return exchange<octomap_rt::ray_reply_t>(channels_.query_rays, q, one<octomap_rt::ray_reply_t>).front();
}

octomap_rt::box_reply_t QueryClient::boxes(const std::vector<Box>& boxes, int8_t mode, const WaitFor& w) {
  octomap_rt::box_query_t q{};
  address(q, w);
  q.mode = mode;
  for (const Box& b : boxes)
    q.boxes.insert(q.boxes.end(), {b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]});
  q.num_values = static_cast<int32_t>(q.boxes.size());
  return exchange<octomap_rt::box_reply_t>(channels_.query_boxes, q, one<octomap_rt::box_reply_t>).front();
}

std::vector<octomap_rt::region_chunk_t> QueryClient::region(const Box& b, int depth, bool include_free,
                                                            const WaitFor& w) {
  octomap_rt::box_query_t q{};
  address(q, w);
  q.mode = octomap_rt::box_query_t::MODE_REGION;
  q.depth = depth;
  q.include_free = include_free;
  q.boxes = {b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]};
  q.num_values = 6;
  auto chunks = exchange<octomap_rt::region_chunk_t>(channels_.query_boxes, q, all_chunks<octomap_rt::region_chunk_t>);
  std::sort(chunks.begin(), chunks.end(), [](const auto& a, const auto& b) { return a.chunk_index < b.chunk_index; });
  return chunks;
}

Grid QueryClient::grid(double z_min, double z_max, double cell_size, const Box* window, const WaitFor& w) {
  octomap_rt::grid_query_t q{};
  address(q, w);
  q.z_min = z_min, q.z_max = z_max, q.cell_size = cell_size;
  q.use_window = window != nullptr;
  if (window) {
    q.window_min[0] = window->min[0], q.window_min[1] = window->min[1];
    q.window_max[0] = window->max[0], q.window_max[1] = window->max[1];
  }
  auto rows = exchange<octomap_rt::grid_t>(channels_.query_grid, q, all_chunks<octomap_rt::grid_t>);
  Grid g;
  g.header = rows.front();
  g.header.cells.clear();
  g.header.num_cells = 0;
  if (g.header.status != 0) return g;
  g.cells.assign(size_t(g.header.width) * g.header.height, 0);
  for (const auto& r : rows)
    std::copy(r.cells.begin(), r.cells.end(), g.cells.begin() + size_t(r.row_start) * g.header.width);
  return g;
}

namespace {
octomap_rt::distance_query_t distance_query(int8_t mode, const DistanceRequest& d) {
  octomap_rt::distance_query_t q{};
  q.mode = mode;
  q.max_distance = d.max_distance;
  q.unknown_as = d.unknown_occupied ? q.UNKNOWN_OCCUPIED : q.UNKNOWN_FREE;
  q.with_gradient = d.gradient;
  q.cell_voxels = d.cell_voxels;
  return q;
}
}  // namespace

template <class Reply>
Reply QueryClient::distance_xyz(int8_t mode, const std::vector<float>& xyz, const DistanceRequest& d,
                                const WaitFor& w) {
  auto q = distance_query(mode, d);
  address(q, w);
  q.xyz = xyz;
  q.num_xyz = static_cast<int32_t>(xyz.size());
  return exchange<Reply>(channels_.query_distance, q, one<Reply>).front();
}

octomap_rt::distance_points_reply_t QueryClient::distance_points(const std::vector<float>& xyz,
                                                                 const DistanceRequest& d, const WaitFor& w) {
  return distance_xyz<octomap_rt::distance_points_reply_t>(octomap_rt::distance_query_t::MODE_POINTS, xyz, d, w);
}

DistanceBox QueryClient::distance_box(const Box& b, const DistanceRequest& d, const WaitFor& w) {
  auto q = distance_query(octomap_rt::distance_query_t::MODE_BOX, d);
  address(q, w);
  std::copy(b.min, b.min + 3, q.box_min);
  std::copy(b.max, b.max + 3, q.box_max);
  const auto chunks = exchange<octomap_rt::distance_box_chunk_t>(channels_.query_distance, q,
                                                                 all_chunks<octomap_rt::distance_box_chunk_t>);
  return assemble_distance_box(chunks);
}

octomap_rt::distance_path_reply_t QueryClient::distance_path(const std::vector<float>& vertices,
                                                             const DistanceRequest& d, const WaitFor& w) {
  return distance_xyz<octomap_rt::distance_path_reply_t>(octomap_rt::distance_query_t::MODE_PATH, vertices, d, w);
}

octomap_rt::map_edit_ack_t QueryClient::edit(int8_t op, const Box& b, const std::string& token, int8_t flags) {
  octomap_rt::map_edit_t e{};
  e.utime = now_utime();
  e.request_id = next_request_++;
  e.op = op;
  e.flags = flags;
  std::copy(b.min, b.min + 3, e.box_min);
  std::copy(b.max, b.max + 3, e.box_max);
  e.nonce = protocol::random_edit_nonce();
  e.client_id = client_id_;
  e.reply_channel = reply_channel_;
  protocol::sign_edit(e, token, channels_.map_edit);
  return exchange<octomap_rt::map_edit_ack_t>(channels_.map_edit, e, one<octomap_rt::map_edit_ack_t>).front();
}

}  // namespace ort::client
