#include "protocol/zstd_codec.h"

#include <zstd.h>

namespace ort::protocol {
namespace {

// The sum of the content sizes the frames of `data` declare (ZSTD_findDecompressedSize is not in
// zstd's stable API); ZSTD_CONTENTSIZE_ERROR / _UNKNOWN as ZSTD_getFrameContentSize says them.
unsigned long long frames_content_size(std::string_view data) {
  if (data.empty()) return ZSTD_CONTENTSIZE_ERROR;
  unsigned long long total = 0;
  while (!data.empty()) {
    const unsigned long long size = ZSTD_getFrameContentSize(data.data(), data.size());
    if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN) return size;
    const size_t frame = ZSTD_findFrameCompressedSize(data.data(), data.size());
    if (ZSTD_isError(frame) || frame == 0) return ZSTD_CONTENTSIZE_ERROR;
    if (size > ~0ull - total) return ZSTD_CONTENTSIZE_ERROR;
    total += size;
    data.remove_prefix(frame);
  }
  return total;
}

}  // namespace

std::string zstd_compress(std::string_view raw, int level) {
  std::string out(ZSTD_compressBound(raw.size()), '\0');
  const size_t n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), level);
  if (ZSTD_isError(n)) throw CodecError(std::string("zstd compress: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

std::string zstd_decompress(std::string_view compressed, size_t max_size) {
  // One frame or several concatenated (a distance box's z-slabs): the sum of their declared sizes.
  const unsigned long long size = frames_content_size(compressed);
  if (size == ZSTD_CONTENTSIZE_ERROR) throw CodecError("zstd: not zstd frames");
  if (size == ZSTD_CONTENTSIZE_UNKNOWN) throw CodecError("zstd: a frame without content size");
  if (size > max_size) throw CodecError("zstd: content of " + std::to_string(size) + " bytes exceeds the limit");
  std::string out(static_cast<size_t>(size), '\0');
  const size_t n = ZSTD_decompress(out.data(), out.size(), compressed.data(), compressed.size());
  if (ZSTD_isError(n)) throw CodecError(std::string("zstd decompress: ") + ZSTD_getErrorName(n));
  if (n != size) throw CodecError("zstd: frames decompressed to another size than they declare");
  return out;
}

}  // namespace ort::protocol
