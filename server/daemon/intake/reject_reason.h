// Why a scan message was not integrated. Every message on a scan channel ends as applied,
// rejected (invalid) or dropped (valid, but not applied: queue full, ...) with exactly one
// of these reasons; the names are what status messages, logs and tests show.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace ort::daemon {

enum class Reject {
  kNone = 0,
  // Wire-level checks, made on the raw bytes BEFORE the generated decode() runs (decode
  // throws or allocates gigabytes on corrupt lengths; see ../shared/notes/lcm-1.3.1.md §0.8).
  kTooLarge,          // message larger than the size bound
  kTruncated,         // shorter than its fixed fields
  kWrongFingerprint,  // first 8 bytes are not scan_t's fingerprint
  kNegativeCount,     // num_xyz < 0
  kCountTooLarge,     // num_xyz above the configured maximum points per scan
  kCountExceedsData,  // num_xyz (or a string length) needs more bytes than the message has
  kTrailingBytes,     // the message has more bytes than its counts account for
  kBadStringLength,   // a string length field < 1 (LCM counts the NUL) or implausibly long
  kDecodeFailed,      // decode() threw or returned an error despite the checks
  // Content checks on the decoded message.
  kCountNotMultipleOf3,
  kNonFinitePose,
  kZeroQuaternion,
  kNonUnitQuaternion,  // | |q| - 1 | > 1e-3
  kBadMaxRange,        // NaN or infinite
  kMaxRangeTooSmall,   // positive, below kMinMaxRange (1 mm): every ray would end in the sensor's voxel
  kUnknownPointsFrame,
  kBadRobotId,        // empty, too long, or outside [A-Za-z0-9_-]
  kRobotIdMismatch,   // robot_id differs from the channel's suffix
  kOriginOutsideMap,  // sensor origin outside the map's key range (OctoMap skips the scan)
  kTooManyProducers,  // more scan channels than --max-producers
  kRobotNotAllowed,   // the channel's robot is not on the --allow-robot list
  kEngineError,       // the engine threw while shooting or applying this scan
  kRayTooLong,        // a ray's walk is longer than OctoMap's KeyRay holds (points km away at fine -r)
  kTooMuchWork,       // the scan's ray walks exceed the per-scan work bound (--max-scan-work)
  kTooManyVoxels,     // the shot scan updates more voxels than --max-scan-voxels
  kMeanRayTooLong,    // its rays are longer on average than --max-mean-ray-voxels (few points, far out)
  kOriginJump,        // the origin is farther from the robot's last scan than it could have moved
  kNewNodeRate,       // the robot's new nodes passed --max-new-nodes-per-s (its allowance is spent)
  kMapNewNodeRate,    // all robots' new nodes passed --max-map-new-nodes-per-s (the map's allowance is spent)
  kDuplicateSeq,      // the seq and utime of the robot's previous scan again: a copy, not applied twice
  kPredictedTooSlow,  // predicted to take more of the stages than --max-scan-time while others stream
  // Why a valid scan was dropped (counted as dropped, not rejected).
  kQueueFull,         // the producer's queue budget was full on arrival
  kOverLatencyBound,  // waited in the queue longer than --max-queue-age (overload shedding)
  kOverShare,         // waited past --latency-bound while other producers were served in its turn (intake/scan_queue.h)
  kLeftAtShutdown,    // still queued when the drain deadline passed at stop
  kCount_
};

inline constexpr std::size_t kRejectReasonCount = static_cast<std::size_t>(Reject::kCount_);

// Stable human-readable name ("truncated", "non-finite pose", ...).
const char* to_string(Reject r);

// Why single points of an applied scan gave no ray (the scan itself is applied with the rest).
// Organised clouds (Ouster, Velodyne, depth cameras) carry NaN for every no-return, so these
// are counted per producer, never a reason to refuse the scan.
enum class PointDrop {
  kNonFinite = 0,    // NaN or infinite coordinate (a no-return), or made infinite by the pose
  kOutsideKeyRange,  // the ray's end lies outside the map's key range (OctoMap skips it too)
  kDegenerateRay,    // nearer than kMinRayLength to the sensor across a voxel border (core/prepare_scan.h)
  // The server's point filters (daemon/pipeline/point_filters.h: octomap_server's pass-through and a min range).
  kOutsideSensorBox,  // outside --sensor-min/max-x/y/z (the points as the sensor sent them)
  kOutsideMapBox,     // outside --pointcloud-min/max-x/y/z (octomap_server's pointcloud_min_z, ...)
  kBelowMinRange,     // nearer the sensor than --min-range
  kCount_
};

inline constexpr std::size_t kPointDropReasonCount = static_cast<std::size_t>(PointDrop::kCount_);
using PointDropCounts = std::array<int64_t, kPointDropReasonCount>;

// Stable human-readable name ("non-finite", ...).
const char* to_string(PointDrop d);

}  // namespace ort::daemon
