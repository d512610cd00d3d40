// Which LCM URL a client uses when none is given.
#pragma once

#include <string>

namespace ort::cli {

// The URL the daemon listens on by default: host-local multicast (ttl=0: packets never
// leave the host). $LCM_DEFAULT_URL wins, as in every LCM program.
inline constexpr const char* kHostLocalLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

// `requested` if not empty, else $LCM_DEFAULT_URL, else kHostLocalLcmUrl.
std::string client_lcm_url(const std::string& requested);

}  // namespace ort::cli
