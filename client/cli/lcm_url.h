// Which LCM URL a client uses when none is given.
#pragma once

#include <string>

namespace ort::cli {

// `requested` if not empty, else $LCM_DEFAULT_URL (as in every LCM program), else the URL the
// daemon listens on by default (octomap_rt::wire::kDefaultLcmUrl: host-local multicast).
std::string client_lcm_url(const std::string& requested);

}  // namespace ort::cli
