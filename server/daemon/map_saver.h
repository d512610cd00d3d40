// The map file's saves: every --save-interval while the server runs (on a thread of its own,
// only when the map changed since the last save), on request (SIGUSR1, tests), and the clean
// save of an orderly stop. A save copies the map under its lock (a state between two whole
// scans) and serializes and writes outside it; the order file is synced first, then the map
// is written, then its identity (docs/PROTOCOL.md "Ids"), each atomically.
//
// Usage: construct once the map is loaded, with mark_saved() for a map that came from the
// file; start() once the map is served; stop() (joins the periodic thread) once the pipeline
// has drained, then save_final(). save() may be called from any thread at any time: saves
// run one at a time. Without a map path every call is a no-op.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include "core/log.h"
#include "core/threads/periodic_thread.h"
#include "daemon/map/map_state.h"
#include "daemon/persistence/map_identity_file.h"

namespace ort::daemon {

// What the status and the run summary say of the saves.
struct SaveFigures {
  int64_t saves = 0, last_save_utime = 0;
  double last_save_ms = 0, max_save_lock_ms = 0;  // the latest save's whole time; the longest map hold
  std::string last_error;                         // "" unless the latest periodic save failed
};

// `map_path` relative or absolute ("": no saves); interval_s <= 0: no periodic saves.
class MapSaver {
 public:
  MapSaver(std::string map_path, double interval_s, MapState& map, Log log);
  ~MapSaver() { stop(); }
  MapSaver(const MapSaver&) = delete;
  MapSaver& operator=(const MapSaver&) = delete;

  // The map as loaded is what the file holds: no save until it changes.
  void mark_saved(uint64_t version) { saved_version_ = version; }
  // Writes the map's identity beside it (FILE.ot.identity) now.
  void write_identity(const MapIdentityRecord& r);
  // The map file's path made absolute (what the identity records).
  std::string absolute_map_path() const;

  void start();
  // Wakes and joins the periodic thread (a save in progress finishes first). Idempotent.
  void stop();

  // Saves now if the map changed since the last save (or `force`); `clean`: the last save of
  // an orderly stop (the identity says so). Throws MapStoreError or std::runtime_error (the
  // previous map file is intact). `from_record`: the map of record, never the read replica.
  void save(bool force = false, bool clean = false, bool from_record = false);
  // The forced, clean save of an orderly stop, of the map of record (the stages have
  // stopped; the replica may be behind). Never throws: "" or why it failed (logged).
  std::string save_final();

  SaveFigures figures() const;

 private:
  void save_periodically();  // on the periodic thread: a save if the map changed, its error kept

  const std::string path_;
  const double interval_s_;
  MapState& map_;
  Log log_;

  std::mutex save_mutex_;  // one save at a time
  uint64_t saved_version_ = UINT64_MAX;
  // Written by the save, read by the status without waiting for a save in progress.
  std::atomic<int64_t> saves_{0}, last_save_utime_{0};
  std::atomic<double> max_save_lock_ms_{0}, last_save_ms_{0};

  mutable std::mutex error_mutex_;  // last_error_
  std::string last_error_;
  PeriodicThread periodic_;  // last: stopped before the members its task uses go
};

}  // namespace ort::daemon
