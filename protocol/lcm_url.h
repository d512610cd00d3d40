// The default-URL rule, the same for the server and every client: the URL given, else
// $LCM_DEFAULT_URL (as in every LCM program), else kDefaultLcmUrl.
#pragma once

#include <string>

namespace ort::protocol {

// Host-local multicast (ttl=0: packets never leave the host). The server adds a receive
// buffer size to udpm URLs (daemon/transport/server_lcm_url.h); a recording or listening tool
// on the same URL needs one too (README, "Recording").
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

// `requested` if not empty, else $LCM_DEFAULT_URL if set and not empty, else kDefaultLcmUrl.
std::string lcm_url_or_default(const std::string& requested);

}  // namespace ort::protocol
