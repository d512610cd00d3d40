#include "protocol/zstd_codec.h"

#include <zstd.h>

namespace ort::protocol {

std::string zstd_compress(std::string_view raw, int level) {
  std::string out(ZSTD_compressBound(raw.size()), '\0');
  const size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), level);
  if (ZSTD_isError(n)) throw CodecError(std::string("zstd compress: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

std::string zstd_decompress(std::string_view compressed, size_t max_size) {
  const unsigned long long size = ZSTD_getFrameContentSize(compressed.data(), compressed.size());
  if (size == ZSTD_CONTENTSIZE_ERROR) throw CodecError("zstd: not a zstd frame");
  if (size == ZSTD_CONTENTSIZE_UNKNOWN) throw CodecError("zstd: frame without content size");
  if (size > max_size) throw CodecError("zstd: content of " + std::to_string(size) + " bytes exceeds the limit");
  std::string out(static_cast<size_t>(size), '\0');
  const size_t n = ZSTD_decompress(out.data(), out.size(), compressed.data(), compressed.size());
  if (ZSTD_isError(n)) throw CodecError(std::string("zstd decompress: ") + ZSTD_getErrorName(n));
  if (n != size) throw CodecError("zstd: frame decompressed to another size than it declares");
  return out;
}

}  // namespace ort::protocol
