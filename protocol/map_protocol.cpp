#include "protocol/map_protocol.h"

namespace ort::protocol {

bool valid_name(std::string_view s) {
  if (s.empty() || s.size() > kMaxNameLength) return false;
  for (char c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

std::string reply_channel_for(std::string_view client_id) {
  std::string ch = kMapReplyPrefix;
  for (char c : client_id) ch += (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : (c == '-' ? '_' : c);
  return ch;
}

}  // namespace ort::protocol
