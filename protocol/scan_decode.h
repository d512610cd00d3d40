// Decoding a scan_t on the LCM thread without LCM's per-float loop. LCM's generated decode
// assembles each float of the point array from four bytes (and the content check then tests
// each for finiteness one by one), on the LCM thread, inside every scan's end-to-end time
// (the log's "the daemon's host work on a scan"). Here the fixed fields and the strings
// are still decoded by LCM's own code, and only the point array is byte-swapped in blocks the
// compiler vectorizes; the values are the same bit for bit (NaN payloads included).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "octomap_rt/scan_t.hpp"

namespace ort::protocol {

// Decodes `data` (a message check_scan_bytes accepted: fingerprint, counts and string lengths
// consistent with `size`) into `out`, as scan_t::decode would. Returns the bytes used, or
// < 0 where LCM's decode fails.
int decode_scan(const uint8_t* data, size_t size, octomap_rt::scan_t& out);

// Big-endian 32-bit words (LCM's float encoding) into host floats.
void decode_be_floats(const uint8_t* src, float* dst, size_t count);

}  // namespace ort::protocol
