// libFuzzer target: one raw map_request_t as the map service's LCM handler gets it: the
// protocol's raw-byte check and decode (protocol/inbound_checks), then the service's rules
// (daemon/map_request_rules). Besides memory errors and UB it checks that a message the
// raw-byte check accepts was decoded from exactly its bytes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>

#include "protocol/inbound_checks.h"
#include "protocol/map_request_rules.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  octomap_rt::map_request_t req;
  if (!ort::protocol::check_request(data, size, req).ok()) return 0;
  octomap_rt::map_request_t again;
  try {
    if (again.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) std::abort();
  } catch (const std::exception&) {
    std::abort();
  }
  (void)ort::protocol::check_map_request(req);
  (void)ort::protocol::can_reply(req);
  return 0;
}
