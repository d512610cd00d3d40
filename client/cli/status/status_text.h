// octomap-rt-server's status (OCTOMAP_RT_STATUS) laid out for a terminal: state, back end,
// rates, latencies, queue, then one row per robot with its reject reasons, then the query
// service's totals, refusal reasons and one row per query client.
#pragma once

#include <cstdint>
#include <string>

#include "octomap_rt/server_status_t.hpp"

namespace ort::status {

// "RUNNING", "DEGRADED", ... ("STATE 7" for a value this client does not know).
std::string state_name(int8_t state);

// The status as text lines (each ending in '\n'), at most ~100 columns wide except for
// long names. `now_utime` (us since the epoch) dates "last save 12 s ago" and the message age.
std::string format_status(const octomap_rt::server_status_t& s, int64_t now_utime);

// 1234567 -> "1,234,567"; bytes -> "10.2 MiB"; seconds -> "1:02:03"; 1.5e6 -> "1.50 M", 4277 -> "4.3 k".
std::string with_commas(int64_t v);
std::string bytes_text(int64_t bytes);
std::string duration_text(double seconds);
std::string rate_text(double per_s);

}  // namespace ort::status
