// libFuzzer target: one raw map_request_t as the map service's LCM handler gets it: the
// protocol's raw-byte check and decode (protocol/inbound_checks), then the service's rules
// (daemon/map_request_rules). Besides memory errors and UB it checks that a message the
// raw-byte check accepts was decoded from exactly its bytes, and that the chunks a request
// makes the server send are each sent once (its reply bytes are at most the snapshot's).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <vector>

#include "protocol/channels.h"
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
  if (ort::protocol::check_map_request(req, ort::protocol::kMapReplyPrefix) != ort::protocol::RequestRefusal::kNone)
    return 0;
  (void)ort::protocol::can_reply(req, ort::protocol::kMapReplyPrefix);
  // Bytes it makes the server send: each chunk of the snapshot at most once, whatever the
  // request repeats (a snapshot of 64 chunks here; indices past it are refused first).
  constexpr int32_t kChunks = 64;
  for (int32_t i : req.chunk_indices)
    if (i >= kChunks) return 0;
  const std::vector<int32_t> sent = ort::protocol::chunks_to_send(req.chunk_indices, kChunks);
  if (sent.size() > size_t(kChunks)) std::abort();
  for (size_t i = 1; i < sent.size(); ++i)
    if (sent[i] <= sent[i - 1]) std::abort();
  return 0;
}
