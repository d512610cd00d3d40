#include "daemon/server_config.h"

#include <unistd.h>

#include <algorithm>

#include "daemon/intake/producer_registry.h"

namespace ort::daemon {

uint64_t automatic_queue_budget() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  const uint64_t phys = pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : (4ull << 30);
  return std::clamp<uint64_t>(phys / 64, 64ull << 20, 1ull << 30);
}

ProducerPolicy producer_policy(const ServerConfig& c) {
  ProducerPolicy p;
  p.max_producers = c.max_producers;
  p.idle_release = std::chrono::duration<double>(c.producer_idle_release_s);
  p.allowed_robots = c.allowed_robots;
  return p;
}

}  // namespace ort::daemon
