// Bounds checks on the raw bytes of the query messages, before decode() (protocol/wire_layout.h
// says why). Each query type keeps its fixed-size fields first, then its counts and arrays,
// then its strings; the layouts below follow the .lcm files. Each returns "" or why not.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace ort::daemon {

// Layouts of the inbound query messages, with the server's limits.
constexpr int64_t kMaxQueryPoints = 5000, kMaxQueryRays = 2000, kMaxQueryBoxes = 1000;
std::string check_occupancy_query(const uint8_t* data, size_t size);
std::string check_ray_query(const uint8_t* data, size_t size);
std::string check_box_query(const uint8_t* data, size_t size);
std::string check_grid_query(const uint8_t* data, size_t size);
std::string check_map_edit(const uint8_t* data, size_t size);

}  // namespace ort::daemon
