#include "protocol/ids.h"

#include "protocol/channels.h"
#include "protocol/limits.h"

namespace ort::protocol {
namespace {

bool id_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}
bool valid_id(std::string_view s, size_t max_length) {
  if (s.empty() || s.size() > max_length) return false;
  for (char c : s)
    if (!id_char(c)) return false;
  return true;
}
char upper(char c) { return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c; }

}  // namespace

bool valid_name(std::string_view s) { return valid_id(s, kMaxNameLength); }
bool valid_robot_id(std::string_view id) { return valid_id(id, kMaxRobotIdLength); }

bool same_robot_id(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (upper(a[i]) != upper(b[i])) return false;
  return true;
}

std::string channel_suffix(std::string_view id) {
  std::string s;
  s.reserve(id.size());
  for (char c : id) s += c == '-' ? '_' : upper(c);
  return s;
}

std::string reply_channel_for(std::string_view client_id, std::string_view prefix) {
  return std::string(prefix) + channel_suffix(client_id);
}
std::string reply_channel_for(std::string_view client_id) { return reply_channel_for(client_id, kMapReplyPrefix); }

std::string check_client_id(std::string_view client_id) {
  if (valid_name(client_id)) return "";
  return "client_id must be 1.." + std::to_string(kMaxNameLength) + " of [A-Za-z0-9_-]";
}

std::string check_reply_channel(std::string_view channel) {
  if (channel.empty() || channel.size() > kMaxChannelLength)
    return "reply_channel must have 1.." + std::to_string(kMaxChannelLength) + " characters";
  for (char c : channel)
    if (!(c > ' ' && c < 127)) return "reply_channel may hold only printable characters";
  return "";
}

}  // namespace ort::protocol
