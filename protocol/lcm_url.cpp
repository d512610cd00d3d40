#include "protocol/lcm_url.h"

#include <cstdlib>

namespace ort::protocol {

std::string lcm_url_or_default(const std::string& requested) {
  if (!requested.empty()) return requested;
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env && *env) return env;
  return kDefaultLcmUrl;
}

}  // namespace ort::protocol
