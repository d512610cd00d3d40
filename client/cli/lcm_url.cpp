#include "cli/lcm_url.h"

#include <cstdlib>

#include "octomap_rt/wire_contract.hpp"

namespace ort::cli {

std::string client_lcm_url(const std::string& requested) {
  if (!requested.empty()) return requested;
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env && *env) return env;
  return octomap_rt::wire::kDefaultLcmUrl;
}

}  // namespace ort::cli
