#include "engine/engine_pipeline.h"

#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

namespace ort {
namespace {

void insert_sequentially(MapEngine& engine, size_t count, const ScanInputSource& source, octomap::OcTree& tree,
                         const AppliedScanSink& sink) {
  ShotScan shot;  // one for all scans: its voxel list's storage is reused
  for (size_t i = 0; i < count; ++i) {
    const PosedScanInput in = source(i);
    engine.insert_posed(in.pose, in.origin, in.sensor_points, tree, shot);
    if (sink) sink(i, shot);
  }
}

// Two ShotScan buffers: stage 1 fills slot i % 2 (shoot_posed resets it, keeping its voxel
// list's storage) while stage 2 applies the other. Stage 1 may shoot scan i once scan i-2
// was applied (its buffer is free again), which bounds the scans shot but not yet applied to
// one beyond the one being applied.
class TwoStageRun {
 public:
  TwoStageRun(MapEngine& engine, octomap::OcTree& tree, const AppliedScanSink& sink)
      : engine_(engine), tree_(tree), sink_(sink) {}

  void run(size_t count, const ScanInputSource& source) {
    std::thread stage2([this] { run_stage2(); });
    std::exception_ptr stage1_error;
    try {
      for (size_t i = 0; i < count; ++i) {
        if (!wait_for_free_slot(i)) break;  // stage 2 failed: its error is rethrown below
        const PosedScanInput in = source(i);
        engine_.shoot_posed(in.pose, in.origin, in.sensor_points, engine_.options().max_range, slots_[i % 2]);
        publish(i);
      }
    } catch (...) {
      stage1_error = std::current_exception();
    }
    finish(stage1_error != nullptr);
    stage2.join();
    if (stage1_error) std::rethrow_exception(stage1_error);
    if (stage2_error_) std::rethrow_exception(stage2_error_);
  }

 private:
  bool wait_for_free_slot(size_t i) {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return stage2_error_ || applied_ + 2 > i; });
    return !stage2_error_;
  }

  void publish(size_t i) {
    {
      std::lock_guard lock(mutex_);
      shot_ = i + 1;
    }
    changed_.notify_all();
  }

  // No more scans: stage 2 applies what was shot and ends (at once when `abort`).
  void finish(bool abort) {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
      aborted_ = abort;
    }
    changed_.notify_all();
  }

  void run_stage2() {
    for (size_t i = 0;; ++i) {
      {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return aborted_ || shot_ > i || closed_; });
        if (aborted_ || shot_ <= i) return;
      }
      try {
        engine_.apply(slots_[i % 2], tree_);
        if (sink_) sink_(i, slots_[i % 2]);
      } catch (...) {
        std::lock_guard lock(mutex_);
        stage2_error_ = std::current_exception();
        changed_.notify_all();
        return;
      }
      {
        std::lock_guard lock(mutex_);
        applied_ = i + 1;
      }
      changed_.notify_all();
    }
  }

  MapEngine& engine_;
  octomap::OcTree& tree_;
  const AppliedScanSink& sink_;
  ShotScan slots_[2];
  std::mutex mutex_;
  std::condition_variable changed_;
  size_t shot_ = 0, applied_ = 0;  // scans handed to stage 2 / applied by it
  bool closed_ = false, aborted_ = false;
  std::exception_ptr stage2_error_;
};

}  // namespace

void insert_scans(MapEngine& engine, size_t count, const ScanInputSource& source, octomap::OcTree& tree,
                  const AppliedScanSink& sink, bool pipelined) {
  if (!pipelined || count < 2) return insert_sequentially(engine, count, source, tree, sink);
  TwoStageRun(engine, tree, sink).run(count, source);
}

}  // namespace ort
