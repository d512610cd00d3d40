#include "map_client/map_client.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <random>
#include <sstream>

#include <octomap/AbstractOcTree.h>

#include "core/clock.h"
#include "map_client/snapshot_assembly.h"
#include "octomap_rt/map_request_t.hpp"
#include "protocol/ids.h"
#include "protocol/inbound_checks.h"
#include "protocol/limits.h"
#include "protocol/version.h"
#include "protocol/zstd_codec.h"

namespace ort::client {
namespace {

using Chunk = octomap_rt::map_chunk_t;

std::string default_client_id() {
  std::random_device rd;
  return "client_" + std::to_string(::getpid()) + "_" + std::to_string(rd() % 100000);
}

}  // namespace

std::unique_ptr<octomap::OcTree> FetchedSnapshot::tree() const {
  std::istringstream in(bytes);
  if (format == Chunk::FORMAT_OCTOMAP_BINARY) {
    auto t = std::make_unique<octomap::OcTree>(0.1);
    if (!t->readBinary(in)) throw FetchError(FetchError::kCorrupt, "snapshot is not a readable .bt map");
    return t;
  }
  std::unique_ptr<octomap::AbstractOcTree> a(octomap::AbstractOcTree::read(in));
  auto* t = dynamic_cast<octomap::OcTree*>(a.get());
  if (!t) throw FetchError(FetchError::kCorrupt, "snapshot is not a readable .ot OcTree");
  a.release();
  return std::unique_ptr<octomap::OcTree>(t);
}

MapClient::MapClient(const std::string& url, ClientOptions opts) : opts_(std::move(opts)), lcm_(url) {
  if (!lcm_.good()) throw std::runtime_error("LCM could not start on '" + url + "'");
  if (opts_.client_id.empty()) opts_.client_id = default_client_id();
  if (std::string why = protocol::check_client_id(opts_.client_id); !why.empty())
    throw std::invalid_argument("client id '" + opts_.client_id + "': " + why);
  reply_channel_ = protocol::reply_channel_for(opts_.client_id, opts_.reply_prefix);
  if (std::string why = protocol::check_channel_length(reply_channel_); !why.empty())
    throw std::invalid_argument("client id '" + opts_.client_id + "': " + why);
  // Subscribed before any handle runs (this object's thread is the only one handling).
  lcm_.subscribe(reply_channel_, &MapClient::on_chunk_bytes, this)->setQueueCapacity(0);
  lcm_.subscribe(opts_.info_channel, &MapClient::on_info_bytes, this);
}

MapClient::~MapClient() = default;

void MapClient::on_chunk_bytes(const lcm::ReceiveBuffer* rb, const std::string&) {
  Chunk c{};
  if (const protocol::WireCheck check = protocol::check_chunk(rb->data, rb->data_size, c); !check.ok()) {
    inbound_.refused["chunk: " + protocol::describe(check)]++;
    return;
  }
  if (c.client_id != opts_.client_id) return;  // another client sharing our id's channel
  inbound_.chunks++;
  chunks_.push_back(std::move(c));
}

void MapClient::on_info_bytes(const lcm::ReceiveBuffer* rb, const std::string&) {
  octomap_rt::map_info_t m{};
  if (const protocol::WireCheck check = protocol::check_info(rb->data, rb->data_size, m); !check.ok()) {
    inbound_.refused["info: " + protocol::describe(check)]++;
    if (check.fault == protocol::WireFault::kWrongFingerprint)
      inbound_.foreign_version = protocol::describe_foreign_version(static_cast<const uint8_t*>(rb->data),
                                                                    rb->data_size, octomap_rt::map_info_t::getHash());
    return;
  }
  inbound_.infos++;
  info_ = std::move(m);
  if (info_handler_) info_handler_(*info_);
}

void MapClient::on_delta_bytes(const lcm::ReceiveBuffer* rb, const std::string&) {
  octomap_rt::map_delta_t d{};
  if (const protocol::WireCheck check = protocol::check_delta(rb->data, rb->data_size, d); !check.ok()) {
    inbound_.refused["delta: " + protocol::describe(check)]++;
    return;
  }
  inbound_.deltas++;
  if (opts_.drop_delta && opts_.drop_delta(d)) return;
  if (delta_handler_) delta_handler_(d);
}

void MapClient::on_delta(std::function<void(const octomap_rt::map_delta_t&)> handler) {
  delta_handler_ = std::move(handler);
  if (!delta_sub_) {
    delta_sub_ = lcm_.subscribe(opts_.delta_channel, &MapClient::on_delta_bytes, this);
    delta_sub_->setQueueCapacity(0);
  }
}

void MapClient::on_info(std::function<void(const octomap_rt::map_info_t&)> handler) {
  info_handler_ = std::move(handler);
}

void MapClient::handle_for(double seconds) {
  const int ms = std::max(0, static_cast<int>(seconds * 1000));
  if (lcm_.handleTimeout(ms) < 0) throw std::runtime_error("LCM handle failed");
}

void MapClient::spin(double timeout_s) {
  const auto t0 = SteadyClock::now();
  do {
    handle_for(std::min(0.05, std::max(0.0, timeout_s - seconds_since(t0))));
  } while (seconds_since(t0) < timeout_s);
}

std::optional<octomap_rt::map_info_t> MapClient::wait_info(double timeout_s) {
  info_.reset();
  const auto t0 = SteadyClock::now();
  while (!info_ && seconds_since(t0) < timeout_s) handle_for(std::min(0.05, timeout_s - seconds_since(t0)));
  return info_;
}

void MapClient::send_request(int64_t request_id, int64_t snapshot_id, int8_t format,
                             const std::vector<int32_t>& indices) {
  octomap_rt::map_request_t r{};
  r.utime = now_utime();
  r.request_id = request_id;
  r.snapshot_id = snapshot_id;
  r.format = format;
  r.chunk_indices = indices;
  if (r.chunk_indices.size() > static_cast<size_t>(protocol::kMaxRequestedChunks))
    r.chunk_indices.resize(protocol::kMaxRequestedChunks);
  r.num_chunk_indices = static_cast<int32_t>(r.chunk_indices.size());
  r.client_id = opts_.client_id;
  r.reply_channel = reply_channel_;
  lcm_.publish(opts_.request_channel, &r);
}

namespace {

// The seconds a busy refusal asks to wait ("... retry after 250 ms"); 0.2 s when it names none.
double busy_retry_s(const std::string& error) {
  const size_t at = error.find("retry after ");
  if (at == std::string::npos) return 0.2;
  try {
    return std::clamp(std::stod(error.substr(at + 12)) / 1000.0, 0.05, 5.0);
  } catch (const std::exception&) {
    return 0.2;
  }
}

}  // namespace

FetchedSnapshot MapClient::fetch_snapshot(int8_t format, double timeout_s, const FetchProgress& progress,
                                          int64_t snapshot_id) {
  const auto t0 = SteadyClock::now();
  FetchedSnapshot out;
  SnapshotAssembly as;
  chunks_.clear();
  const int64_t first_request = next_request_id_;
  send_request(next_request_id_++, snapshot_id, format, {});
  out.requests = 1;
  auto last_arrival = SteadyClock::now();
  auto retry_at = SteadyClock::time_point::max();  // refused as busy: ask again then (max: not refused)
  std::minstd_rand rng(static_cast<unsigned>(std::random_device{}()));
  while (!as.complete()) {
    if (seconds_since(t0) >= timeout_s) {
      std::ostringstream why;
      why << "no complete snapshot within " << timeout_s << " s: ";
      if (as.started())
        why << as.received() << " of " << as.num_chunks() << " chunks after " << out.requests << " requests";
      else
        why << "no answer to " << out.requests << " requests (is octomap-rt-server running on this LCM URL?)";
      if (!inbound_.foreign_version.empty()) why << "; " << inbound_.foreign_version;
      throw FetchError(FetchError::kTimeout, why.str());
    }
    handle_for(std::min(0.02, timeout_s - seconds_since(t0)));
    for (Chunk& c : chunks_) {
      if (c.request_id < first_request) continue;  // an answer to an earlier fetch
      if (!c.error.empty()) {
        // A re-send of a snapshot the server no longer keeps: start over with a fresh one.
        if (as.started() && c.error.rfind("snapshot not kept", 0) == 0) {
          as = SnapshotAssembly{};
          send_request(next_request_id_++, -1, format, {});
          out.requests++;
          continue;
        }
        // Busy (many clients at once): ask again after the time the server names, stretched
        // by a random quarter to half so that clients refused together do not return together.
        if (c.error.rfind("busy", 0) == 0) {
          out.busy_replies++;
          retry_at =
              SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(
                                       busy_retry_s(c.error) * std::uniform_real_distribution<double>(1.25, 1.5)(rng)));
          continue;
        }
        throw FetchError(FetchError::kRefused, "the server refused the request: " + c.error);
      }
      if (opts_.drop_chunk && opts_.drop_chunk(c)) {
        out.chunks_dropped++;
        continue;
      }
      const std::string why = as.add(c);
      if (!why.empty()) inbound_.refused["chunk: " + why]++;
      last_arrival = SteadyClock::now();
      if (progress) progress(as.received_bytes(), as.total_size());
    }
    chunks_.clear();
    // Before the first chunk the server may still be copying and compressing a big map: ask
    // again only after a longer silence, so as not to queue duplicate full sends.
    const double patience = as.started() ? opts_.rerequest_after_s : opts_.first_answer_after_s;
    const bool refused = retry_at != SteadyClock::time_point::max();
    // Asked again: the chunks still missing of the snapshot begun, else the whole snapshot.
    auto ask_again = [&] {
      if (as.started())
        send_request(next_request_id_++, as.snapshot_id(), format, as.missing());
      else
        send_request(next_request_id_++, snapshot_id, format, {});
      out.requests++;
      last_arrival = SteadyClock::now();
    };
    if (refused && SteadyClock::now() >= retry_at) {
      retry_at = SteadyClock::time_point::max();
      ask_again();
    } else if (!refused && !as.complete() && seconds_since(last_arrival) >= patience) {
      ask_again();
    }
  }
  std::string blob;
  try {
    blob = as.blob();
  } catch (const std::exception& e) {
    throw FetchError(FetchError::kCorrupt, e.what());
  }
  try {
    out.bytes = as.compression() == Chunk::COMPRESSION_ZSTD
                    ? protocol::zstd_decompress(blob, static_cast<size_t>(as.uncompressed_size()))
                    : blob;
  } catch (const std::exception& e) {
    throw FetchError(FetchError::kCorrupt, std::string("snapshot does not decompress: ") + e.what());
  }
  if (static_cast<int64_t>(out.bytes.size()) != as.uncompressed_size())
    throw FetchError(FetchError::kCorrupt, "snapshot has another size than announced");
  out.snapshot_id = as.snapshot_id();
  out.num_scans = as.num_scans();
  out.map_epoch = as.map_epoch();
  out.format = as.format();
  out.compressed_size = as.total_size();
  out.num_chunks = as.num_chunks();
  out.seconds = seconds_since(t0);
  return out;
}

}  // namespace ort::client
