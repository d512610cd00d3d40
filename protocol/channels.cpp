#include "protocol/channels.h"

#include <cstdlib>
#include <stdexcept>

namespace ort::protocol {

std::string check_namespace(std::string_view ns) {
  for (char c : ns) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok) return "namespace '" + std::string(ns) + "' may hold only letters, digits and '_'";
  }
  return "";
}

std::string namespace_from(const std::string& requested) {
  if (!requested.empty()) return requested;
  if (const char* env = std::getenv(kNamespaceEnv); env && *env) return env;
  return "";
}

std::string in_namespace(std::string_view ns, std::string_view name) {
  if (ns.empty()) return std::string(name);
  std::string out(ns);
  out += '_';
  out += name;
  return out;
}

std::string check_channel_length(std::string_view channel) {
  if (channel.empty()) return "empty channel name";
  if (channel.size() > kMaxChannelLength)
    return "channel " + std::string(channel) + ": " + std::to_string(channel.size()) +
           " characters, LCM takes at most " + std::to_string(kMaxChannelLength);
  return "";
}

Channels channels_in(std::string_view ns) {
  if (std::string why = check_namespace(ns); !why.empty()) throw std::invalid_argument(why);
  Channels c;
  c.ns = std::string(ns);
  const auto name = [&](const char* base) {
    std::string full = in_namespace(ns, base);
    if (std::string why = check_channel_length(full); !why.empty()) throw std::invalid_argument(why);
    return full;
  };
  // Prefixes must leave room for at least one character of id.
  const auto prefix = [&](const char* base) {
    std::string full = in_namespace(ns, base);
    if (std::string why = check_channel_length(full + "X"); !why.empty())
      throw std::invalid_argument("namespace '" + std::string(ns) + "' leaves no room for an id after " + full);
    return full;
  };
  c.scan_prefix = prefix(kScanChannelPrefix);
  c.status = name(kStatusChannel);
  c.map_request = name(kMapRequestChannel);
  c.map_info = name(kMapInfoChannel);
  c.map_delta = name(kMapDeltaChannel);
  c.map_reply_prefix = prefix(kMapReplyPrefix);
  c.query_points = name(kQueryChannel);
  c.query_rays = name(kQueryRaysChannel);
  c.query_boxes = name(kQueryBoxesChannel);
  c.query_grid = name(kQueryGridChannel);
  c.query_distance = name(kQueryDistanceChannel);
  c.map_edit = name(kMapEditChannel);
  c.query_reply_prefix = prefix(kQueryReplyPrefix);
  c.grid = name(kGridChannel);
  c.octomap_raw = name(kOctomapRawChannel);
  return c;
}

}  // namespace ort::protocol
