#include "cli/replay/lcm_server_wait.h"

#include <chrono>

#include "core/clock.h"

namespace ort::cli {
namespace {

void note_status(const lcm::ReceiveBuffer*, const std::string&, bool* seen) { *seen = true; }

}  // namespace

bool wait_for_server_status(lcm::LCM& lcm, const std::string& status_channel, double timeout_s) {
  bool seen = false;
  // Untyped: we only need to know that the server is there, not what it says.
  lcm::Subscription* sub = lcm.subscribeFunction(status_channel, &note_status, &seen);
  const auto deadline = SteadyClock::now() + std::chrono::duration<double>(timeout_s);
  while (!seen && SteadyClock::now() < deadline) {
    if (lcm.handleTimeout(100) < 0) break;
  }
  lcm.unsubscribe(sub);
  return seen;
}

}  // namespace ort::cli
