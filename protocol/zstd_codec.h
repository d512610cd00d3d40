// zstd in and out of memory, with typed errors.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace ort::protocol {

struct CodecError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// level: zstd's 1 (fast) .. 19 (small); values outside are clamped by zstd.
std::string zstd_compress(std::string_view raw, int level);
// One frame or several concatenated (decompressed one after the other). Refuses (CodecError)
// frames whose content sizes are unknown, sum above `max_size` or are not what they
// decompress to, and any corrupt frame.
std::string zstd_decompress(std::string_view compressed, size_t max_size);

}  // namespace ort::protocol
