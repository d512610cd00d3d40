// What every query reply carries besides its answer: the map it was read from (snapshot id,
// epoch, map time), who asked (request and client id), the status and error, and when it was
// sent; and the encoding of a reply into the bytes the LCM loop publishes. One spelling for
// the occupancy, ray, box, region, grid and distance replies.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/clock.h"
#include "octomap_rt/occupancy_reply_t.hpp"

namespace ort::daemon {

// The map a reply was read from.
struct MapStamp {
  int64_t snapshot_id = 0, map_utime = 0;
  int64_t map_epoch = 0;  // the history snapshot_id counts in
};

// Fills the fields every reply message has; a reply that can be cut (rays, boxes) starts
// uncut. `query` is anything with request_id and client_id (a decoded query message or its
// QueryHeader).
template <class Reply, class Query>
void stamp_reply(Reply& m, const Query& query, const MapStamp& s, const std::string& server_id, int8_t status,
                 const std::string& error) {
  m.utime = now_utime();
  m.request_id = query.request_id;
  m.snapshot_id = s.snapshot_id;
  m.map_epoch = s.map_epoch;
  m.map_utime = s.map_utime;
  m.status = status;
  m.server_id = server_id;
  m.client_id = query.client_id;
  m.error = error;
  if constexpr (requires { m.cut_at; }) m.cut = octomap_rt::occupancy_reply_t::CUT_NONE, m.cut_at = -1;
}

// An LCM message's wire bytes.
template <class M>
std::vector<uint8_t> encode_message(const M& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

}  // namespace ort::daemon
