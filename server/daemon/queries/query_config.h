// What the query service is configured with (server flags --control-token, --query-queue,
// --grid-rate, --grid-z, --grid-cell: daemon/query_flags).
#pragma once

#include <cstddef>
#include <string>

#include "protocol/channels.h"

namespace ort::daemon {

// The 2D grid published at a rate (daemon/grid_publisher.h).
struct GridPublishConfig {
  double rate_hz = 0;           // 0: not published
  double z_min = 0, z_max = 0;  // the band [m]
  double cell_size = 0;         // [m]; 0: the resolution; else a multiple of it
  std::string channel = ort::protocol::kGridChannel;
};

struct QueryServiceConfig {
  std::string points_channel = ort::protocol::kQueryChannel;
  std::string rays_channel = ort::protocol::kQueryRaysChannel;
  std::string boxes_channel = ort::protocol::kQueryBoxesChannel;
  std::string grid_channel = ort::protocol::kQueryGridChannel;
  std::string edit_channel = ort::protocol::kMapEditChannel;
  std::string control_token;     // "": every edit is refused
  size_t per_client_queue = 16;  // queued queries per client; more get BUSY
  size_t max_clients = 256;      // distinct client ids tracked; the rest share "*"
  int max_wait_ms = 30000;       // longest wait_timeout_ms honoured
  GridPublishConfig grid;
};

}  // namespace ort::daemon
