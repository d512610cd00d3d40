// Inbound map-protocol messages are checked on their raw bytes before decode(): LCM 1.3.1's
// generated decode() throws or allocates gigabytes on corrupt length fields (see
// ../shared/notes/lcm-1.3.1.md §5.4). Each check bounds the size, compares the fingerprint,
// bounds the variable-length count at its fixed offset, then decodes inside try/catch.
// They return "" when `out` holds the message, else why it was refused.
#pragma once

#include <cstddef>
#include <string>

#include "octomap_rt/map_chunk_t.hpp"
#include "octomap_rt/map_delta_t.hpp"
#include "octomap_rt/map_info_t.hpp"
#include "octomap_rt/map_request_t.hpp"

namespace ort::protocol {

std::string check_chunk(const void* data, size_t size, octomap_rt::map_chunk_t& out);
std::string check_delta(const void* data, size_t size, octomap_rt::map_delta_t& out);
std::string check_info(const void* data, size_t size, octomap_rt::map_info_t& out);
std::string check_request(const void* data, size_t size, octomap_rt::map_request_t& out);

}  // namespace ort::protocol
