// The id rules of the protocol: robot ids (scan channels), client ids (map requests, queries
// and edits: one rule for both services) and the reply channels made from them.
#pragma once

#include <string>
#include <string_view>

namespace ort::protocol {

// 1..kMaxNameLength characters of [A-Za-z0-9_-]: a client id, or a map reply channel name.
bool valid_name(std::string_view s);
// Robot ids: 1..kMaxRobotIdLength of [A-Za-z0-9_-].
bool valid_robot_id(std::string_view id);
// Case-insensitive equality: channel OCTOMAP_RT_SCAN_HUSKY3 carries robot_id "husky3".
bool same_robot_id(std::string_view a, std::string_view b);
// `id` in upper case with '-' as '_': the suffix of a channel named after a robot or client.
std::string channel_suffix(std::string_view id);
// A client's map reply channel: `prefix` (Channels::map_reply_prefix; today's
// OCTOMAP_RT_MAP_REPLY_ by default) + channel_suffix(client_id).
std::string reply_channel_for(std::string_view client_id, std::string_view prefix);
std::string reply_channel_for(std::string_view client_id);
// "" when `channel` may be a query's reply channel (1..63 printable characters), else why not.
std::string check_reply_channel(std::string_view channel);
// "" when `client_id` follows valid_name, else why not (the text goes back to the client).
std::string check_client_id(std::string_view client_id);

}  // namespace ort::protocol
