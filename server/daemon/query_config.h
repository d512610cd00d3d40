// What the query service is configured with (server flags --control-token, --query-queue).
#pragma once

#include <cstddef>
#include <string>

namespace ort::daemon {

struct QueryServiceConfig {
  std::string points_channel = "OCTOMAP_RT_QUERY";
  std::string rays_channel = "OCTOMAP_RT_QUERY_RAYS";
  std::string boxes_channel = "OCTOMAP_RT_QUERY_BOXES";
  std::string grid_channel = "OCTOMAP_RT_QUERY_GRID";
  std::string edit_channel = "OCTOMAP_RT_MAP_EDIT";
  std::string control_token;       // "": every edit is refused
  size_t per_client_queue = 16;    // queued queries per client; more get BUSY
  size_t max_clients = 256;        // distinct client ids tracked; the rest share "*"
  int max_wait_ms = 30000;         // longest wait_timeout_ms honoured
};

}  // namespace ort::daemon
