// Waiting for octomap-rt-server before publishing: its first status message means its
// subscriptions are up, so scans sent after it are not lost to a late start.
#pragma once

#include <string>

#include <lcm/lcm-cpp.hpp>

namespace ort::cli {

// Handles `lcm` until a message arrives on `status_channel` or `timeout_s` pass.
bool wait_for_server_status(lcm::LCM& lcm, const std::string& status_channel, double timeout_s);

}  // namespace ort::cli
