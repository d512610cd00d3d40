#include "daemon/intake/reject_reason.h"

namespace ort::daemon {

const char* to_string(Reject r) {
  switch (r) {
    case Reject::kNone: return "none";
    case Reject::kTooLarge: return "too large";
    case Reject::kTruncated: return "truncated";
    case Reject::kWrongFingerprint: return "wrong fingerprint";
    case Reject::kNegativeCount: return "negative count";
    case Reject::kCountTooLarge: return "count too large";
    case Reject::kCountExceedsData: return "count exceeds data";
    case Reject::kTrailingBytes: return "trailing bytes";
    case Reject::kBadStringLength: return "bad string length";
    case Reject::kDecodeFailed: return "decode failed";
    case Reject::kCountNotMultipleOf3: return "count not a multiple of 3";
    case Reject::kNonFinitePose: return "non-finite pose";
    case Reject::kZeroQuaternion: return "zero quaternion";
    case Reject::kNonUnitQuaternion: return "non-unit quaternion";
    case Reject::kBadMaxRange: return "bad max range";
    case Reject::kMaxRangeTooSmall: return "max range too small";
    case Reject::kUnknownPointsFrame: return "unknown points frame";
    case Reject::kBadRobotId: return "bad robot id";
    case Reject::kRobotIdMismatch: return "robot id does not match channel";
    case Reject::kOriginOutsideMap: return "origin outside map";
    case Reject::kTooManyProducers: return "too many producers";
    case Reject::kRobotNotAllowed: return "robot not allowed";
    case Reject::kEngineError: return "engine error";
    case Reject::kRayTooLong: return "ray too long";
    case Reject::kTooMuchWork: return "too much work";
    case Reject::kTooManyVoxels: return "too many voxels";
    case Reject::kMeanRayTooLong: return "rays too long on average";
    case Reject::kOriginJump: return "origin jump";
    case Reject::kNewNodeRate: return "new-node rate";
    case Reject::kMapNewNodeRate: return "map new-node rate";
    case Reject::kDuplicateSeq: return "duplicate seq";
    case Reject::kPredictedTooSlow: return "predicted too slow";
    case Reject::kQueueFull: return "queue full";
    case Reject::kOverLatencyBound: return "over latency bound";
    case Reject::kOverShare: return "over its share";
    case Reject::kLeftAtShutdown: return "left at shutdown";
    case Reject::kCount_: break;
  }
  return "unknown";
}

const char* to_string(PointDrop d) {
  switch (d) {
    case PointDrop::kNonFinite: return "non-finite";
    case PointDrop::kOutsideKeyRange: return "outside key range";
    case PointDrop::kDegenerateRay: return "degenerate ray";
    case PointDrop::kOutsideSensorBox: return "outside sensor-frame box";
    case PointDrop::kOutsideMapBox: return "outside map-frame box";
    case PointDrop::kBelowMinRange: return "below min range";
    case PointDrop::kCount_: break;
  }
  return "unknown";
}

}  // namespace ort::daemon
