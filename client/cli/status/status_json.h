// octomap-rt-server's status as one line of JSON (every field of server_status_t, robots as
// objects with their reject reasons as a name -> count object; "queries": the query service's
// totals, refusal reasons and clients), for scripts and `jq`.
#pragma once

#include <string>

#include "octomap_rt/server_status_t.hpp"

namespace ort::status {

std::string status_json(const octomap_rt::server_status_t& s);

// A JSON string literal of `text` (quotes included, control characters escaped).
std::string json_string(const std::string& text);

}  // namespace ort::status
