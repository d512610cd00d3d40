#include "daemon/status/process_memory.h"

#include <unistd.h>

#include <fstream>

namespace ort::daemon {

int64_t resident_set_bytes() {
  std::ifstream statm("/proc/self/statm");
  int64_t pages = 0, resident = 0;
  if (!(statm >> pages >> resident)) return -1;
  const long page = ::sysconf(_SC_PAGESIZE);
  return page > 0 ? resident * page : -1;
}

}  // namespace ort::daemon
