// The server's human-readable end-of-run summary (per producer, stage times, overlap, map,
// files), printed from the same inputs as the status message plus what only a person reads.
#pragma once

#include <cstddef>
#include <ostream>
#include <string>

#include "daemon/serving/delta_publisher.h"
#include "daemon/serving/map_service.h"
#include "daemon/status/status_message.h"

namespace ort::daemon {

struct RunSummaryInputs {
  StatusInputs status;
  size_t scans_in_map = 0;  // applied-order entries, earlier runs included
  std::string applied_log;  // "": none
  double last_save_ms = 0, max_save_lock_ms = 0;
  MapServiceStats map_service;
  DeltaStats deltas;
  bool deltas_on = false;
  std::string final_save_error;  // "": the final save worked (or there was none)
};

void print_run_summary(std::ostream& out, const RunSummaryInputs& in);

}  // namespace ort::daemon
