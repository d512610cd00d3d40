// Scan messages recorded by lcm-logger, read back for `octomap-rt replay LOG`.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace ort::cli {

// True if the file starts with an LCM log event (sync word 0xEDA1DA01).
bool is_lcm_log(const std::string& path);

struct LogScanEvent {
  size_t index = 0;       // among the log's scan events (channels with the prefix)
  int64_t timestamp = 0;  // when lcm-logger received it [us since the epoch]
  std::string channel;
  const void* data = nullptr;  // valid only during the callback
  uint32_t size = 0;
};

// Calls `fn` for every event whose channel starts with `prefix`, in log order; stops early
// when fn returns false. Returns the number of other events skipped. Throws
// std::runtime_error when the file cannot be opened as a log.
size_t for_each_log_scan(const std::string& path, const std::string& prefix,
                         const std::function<bool(const LogScanEvent&)>& fn);

}  // namespace ort::cli
