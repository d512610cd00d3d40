// `octomap-rt replay INPUT --robot NAME`: a producer for octomap-rt-server. Publishes the
// scans of a ScanGraph file, the built-in synthetic scene, or an lcm-logger log as
// octomap_rt::scan_t on OCTOMAP_RT_SCAN_<ROBOT>, paced, with a progress bar on stderr.
// Several replays at once act as several robots; --part i/n splits one data set among them.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <thread>
#include <unordered_set>

#include <lcm/lcm-cpp.hpp>

#include "cli/commands.h"
#include "cli/namespace_flag.h"
#include "cli/progress_bar.h"
#include "cli/replay/lcm_log_scans.h"
#include "cli/replay/lcm_server_wait.h"
#include "cli/replay/scan_message.h"
#include "cli/replay/scan_selection.h"
#include "core/clock.h"
#include "core/log.h"
#include "protocol/channels.h"
#include "protocol/lcm_url.h"
#include "protocol/limits.h"
#include "scene/scan_set.h"
#include "scene/synthetic_scene.h"

namespace ort::cli {
namespace {

struct ReplayArgs {
  std::string input;
  std::string robot;
  double rate = 2.0;        // scans/s (finite, > 0)
  bool unpaced = false;     // as fast as publishing goes
  bool rate_given = false;  // logs: --rate replaces the recorded timing
  double speed = 1.0;       // logs: playback speed factor on the recorded timing
  std::string lcm_url;
  std::string ns;  // --namespace
  std::string channel_prefix = ort::protocol::kScanChannelPrefix;
  std::string status_channel = ort::protocol::kStatusChannel;
  double max_range = -1.0;
  std::string points_frame = "sensor";
  std::string part;
  ScanSelection sel;
  int64_t first_seq = 0;
  size_t decimate = 1;
  double wait_for_server_s = 0.0;
  bool quiet = false;
};

// Keeps publications `period` apart without bursts: when publishing falls behind (a large
// message took longer than the period), the schedule restarts from now instead of sending
// the backlog back to back, which would overflow the receivers' socket buffers.
class Pacer {
 public:
  explicit Pacer(double period_s) : period_(period_s) {}
  void wait_turn() {
    const auto now = SteadyClock::now();
    if (!started_) {
      started_ = true;
      next_ = now;
    }
    if (next_ > now) std::this_thread::sleep_until(next_);
    next_ = std::max(next_, SteadyClock::now() - std::chrono::milliseconds(1)) +
            std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(period_));
  }

 private:
  double period_;
  bool started_ = false;
  SteadyClock::time_point next_{};
};

struct ReplayTotals {
  size_t scans = 0;
  uint64_t points = 0;
  uint64_t bytes = 0;
  size_t publish_errors = 0;
  SteadyClock::time_point start = SteadyClock::now();
  SteadyClock::time_point first_publish{};
  // Rate between the first and the last publication: pacing, not start-up, is what it shows.
  std::string detail() const {
    const double s = seconds_since(first_publish);
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.1f MB, %.2f scans/s", bytes / 1e6, scans > 1 && s > 0 ? (scans - 1) / s : 0.0);
    return buf;
  }
};

void print_totals(const char* what, const std::string& channel_desc, const ReplayTotals& t) {
  const double s = seconds_since(t.start);
  std::printf("octomap-rt replay: %s\n", what);
  std::printf("  published:  %zu scans, %llu points, %.1f MB on %s\n", t.scans, (unsigned long long)t.points,
              t.bytes / 1e6, channel_desc.c_str());
  std::printf("  time:       %.2f s, %.2f scans/s, %.1f MB/s\n", s, s > 0 ? t.scans / s : 0.0,
              s > 0 ? t.bytes / 1e6 / s : 0.0);
  if (t.publish_errors) std::printf("  errors:     %zu publish calls failed\n", t.publish_errors);
}

int replay_scan_set(const ReplayArgs& a, lcm::LCM& lc) {
  const ScanSet set = a.input == "synthetic" ? make_synthetic_rooms() : load_scan_graph(a.input);
  const std::vector<size_t> order = select_scans(set.scans.size(), a.sel);
  const std::string channel = scan_channel(a.channel_prefix, a.robot);
  if (order.empty())
    throw std::runtime_error("the selection holds no scans (" + std::to_string(set.scans.size()) + " in " + set.name +
                             ")");

  ScanMessageFields f;
  f.robot_id = a.robot;
  f.max_range = static_cast<float>(a.max_range);
  f.frame = a.points_frame == "map" ? PointsFrame::kMap : PointsFrame::kSensor;
  f.stride = a.decimate;

  Pacer pacer(a.unpaced ? 0.0 : 1.0 / a.rate);
  ProgressBar bar("replay " + a.robot, order.size(), !a.quiet);
  ReplayTotals t;
  std::vector<uint8_t> buf;
  for (size_t k = 0; k < order.size(); ++k) {
    f.seq = a.first_seq + static_cast<int64_t>(k);
    // Encode before waiting for our turn, so the publication itself is what is paced.
    const PosedScan& scan = set.scans[order[k]];
    f.utime = now_utime();
    octomap_rt::scan_t msg = make_scan_message(scan, f);
    buf.resize(msg.getEncodedSize());
    msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
    pacer.wait_turn();
    if (t.scans == 0) t.first_publish = SteadyClock::now();
    if (lc.publish(channel, buf.data(), static_cast<unsigned>(buf.size())) != 0) ++t.publish_errors;
    ++t.scans;
    t.points += msg.xyz.size() / 3;
    t.bytes += buf.size();
    bar.update(t.scans, t.detail());
  }
  bar.finish();
  print_totals(("robot " + a.robot + ", " + std::to_string(order.size()) + " of " + std::to_string(set.scans.size()) +
                " scans of " + set.name)
                   .c_str(),
               channel, t);
  return t.publish_errors ? 1 : 0;
}

// A log: without --robot every recorded scan is republished unchanged (its robot, channel and
// seq); with --robot, scans are renamed to that robot and renumbered, so one log can stand
// in for several robots.
int replay_log(const ReplayArgs& a, lcm::LCM& lc) {
  size_t n = 0;
  for_each_log_scan(a.input, a.channel_prefix, [&](const LogScanEvent&) {
    ++n;
    return true;
  });
  ScanSelection one_pass = a.sel;
  one_pass.repeat = 1;
  const std::vector<size_t> picked = select_scans(n, one_pass);
  if (picked.empty())
    throw std::runtime_error("no scan events (channels " + a.channel_prefix + "*) selected in " + a.input + " (" +
                             std::to_string(n) + " there)");
  const std::unordered_set<size_t> wanted(picked.begin(), picked.end());
  const size_t total = picked.size() * a.sel.repeat;
  const std::string out_channel = a.robot.empty() ? "" : scan_channel(a.channel_prefix, a.robot);

  const bool by_rate = a.rate_given || a.unpaced;
  Pacer pacer(by_rate && !a.unpaced ? 1.0 / a.rate : 0.0);
  ProgressBar bar("replay " + (a.robot.empty() ? std::string("log") : a.robot), total, !a.quiet);
  ReplayTotals t;
  size_t skipped = 0, undecodable = 0;
  std::vector<uint8_t> buf;
  for (size_t r = 0; r < a.sel.repeat; ++r) {
    int64_t first_ts = -1;
    SteadyClock::time_point pass_start{};
    skipped = for_each_log_scan(a.input, a.channel_prefix, [&](const LogScanEvent& e) {
      if (!wanted.count(e.index)) return true;
      const void* data = e.data;
      uint32_t size = e.size;
      std::string channel = e.channel;
      uint64_t points = 0;
      octomap_rt::scan_t msg;
      bool decoded = false;
      try {  // the log may hold anything on these channels; decode() throws on bad lengths
        decoded = msg.decode(e.data, 0, static_cast<int>(e.size)) >= 0;
      } catch (const std::exception&) {}
      if (decoded) points = msg.xyz.size() / 3;
      if (!out_channel.empty()) {
        if (!decoded) {
          ++undecodable;
          return true;
        }
        msg.robot_id = a.robot;
        msg.seq = a.first_seq + static_cast<int64_t>(t.scans);
        buf.resize(msg.getEncodedSize());
        msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
        data = buf.data();
        size = static_cast<uint32_t>(buf.size());
        channel = out_channel;
      }
      if (by_rate) {
        pacer.wait_turn();
      } else {  // the recorded timing, scaled by --speed
        if (first_ts < 0) {
          first_ts = e.timestamp;
          pass_start = SteadyClock::now();
        }
        const double offset_s = (e.timestamp - first_ts) / 1e6 / a.speed;
        std::this_thread::sleep_until(
            pass_start + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(offset_s)));
      }
      if (t.scans == 0) t.first_publish = SteadyClock::now();
      if (lc.publish(channel, data, size) != 0) ++t.publish_errors;
      ++t.scans;
      t.points += points;
      t.bytes += size;
      bar.update(t.scans, t.detail());
      return true;
    });
  }
  bar.finish();
  std::string what = std::to_string(picked.size()) + " of " + std::to_string(n) + " scan events of " + a.input;
  if (a.sel.repeat > 1) what += ", " + std::to_string(a.sel.repeat) + " times";
  print_totals(what.c_str(), out_channel.empty() ? "their recorded channels" : out_channel, t);
  if (skipped) std::printf("  skipped:    %zu events on other channels\n", skipped);
  if (undecodable) std::printf("  skipped:    %zu events that are not scan_t\n", undecodable);
  return t.publish_errors ? 1 : 0;
}

// Rates, speeds and ranges are refused unless they mean something: NaN, infinities and
// rates <= 0 used to be accepted silently.
void check_numbers(const ReplayArgs& a) {
  if (!(std::isfinite(a.rate) && a.rate > 0 && a.rate <= 1e6))
    throw CLI::ValidationError("--rate", "must be a number of scans per second in (0, 1e6] (--unpaced: no pacing)");
  if (!(std::isfinite(a.speed) && a.speed > 0 && a.speed <= 1e6))
    throw CLI::ValidationError("--speed", "must be a factor in (0, 1e6]");
  if (!std::isfinite(a.max_range)) throw CLI::ValidationError("--max-range", "must be a finite number of metres");
  if (a.max_range > 0 && a.max_range < ort::protocol::kMinScanMaxRange)
    throw CLI::ValidationError("--max-range", "must be at least " + std::to_string(ort::protocol::kMinScanMaxRange) +
                                                  " m (or <= 0: the server's applies)");
  if (!(std::isfinite(a.wait_for_server_s) && a.wait_for_server_s >= 0))
    throw CLI::ValidationError("--wait-for-server", "must be a number of seconds >= 0");
}

int run_replay(ReplayArgs a) {
  check_numbers(a);
  const std::string ns = protocol::channels_in(protocol::namespace_from(a.ns)).ns;
  a.channel_prefix = protocol::in_namespace(ns, a.channel_prefix);
  a.status_channel = protocol::in_namespace(ns, a.status_channel);
  if (!a.part.empty()) {
    if (std::string why = parse_part(a.part, a.sel); !why.empty()) throw CLI::ValidationError("--part", why);
  }
  const bool is_log = a.input != "synthetic" && is_lcm_log(a.input);
  if (a.robot.empty() && !is_log) throw CLI::ValidationError("--robot", "is required unless INPUT is an LCM log");
  if (!a.robot.empty()) {
    if (std::string why = check_robot_id(a.robot); !why.empty()) throw CLI::ValidationError("--robot", why);
  }

  const std::string url = ort::protocol::lcm_url_or_default(a.lcm_url);
  lcm::LCM lc(url);
  if (!lc.good())
    throw std::runtime_error("cannot open LCM at " + url +
                             " (for udpm on one host: "
                             "ip route add 224.0.0.0/4 dev lo)");
  if (a.wait_for_server_s > 0) {
    // A separate instance, closed before publishing: a subscribed udpm instance keeps a
    // receive socket that would take in every robot's multi-MB scans with a small buffer
    // and fill the kernel's receive-error counters the server reports.
    lcm::LCM listener(url);
    if (!wait_for_server_status(listener, a.status_channel, a.wait_for_server_s)) {
      log_to(std::cerr, "octomap-rt replay")
          .error(text("no message on ", a.status_channel, " within ", a.wait_for_server_s, " s at ", url,
                      ": is octomap-rt-server running there?"));
      return 2;
    }
  }
  return is_log ? replay_log(a, lc) : replay_scan_set(a, lc);
}

}  // namespace

void register_replay_command(CLI::App& app) {
  auto args = std::make_shared<ReplayArgs>();
  CLI::App* cmd = app.add_subcommand(
      "replay", "publish scans to octomap-rt-server over LCM, as one robot (ScanGraph, synthetic, or LCM log)");
  cmd->add_option("INPUT", args->input,
                  "OctoMap ScanGraph .graph file, 'synthetic' for the built-in scene, or an lcm-logger log")
      ->required();
  cmd->add_option("--robot", args->robot,
                  "robot id: publishes on <channel-prefix><ROBOT> (required, except for logs, whose scans "
                  "keep their robots unless this renames them)");
  auto* rate = cmd->add_option("--rate", args->rate, "scans per second, > 0 (logs: recorded timing unless set)")
                   ->capture_default_str();
  cmd->add_flag("--unpaced", args->unpaced, "publish as fast as possible (no pacing)");
  cmd->add_option("--speed", args->speed, "logs: speed factor on the recorded timing")->capture_default_str();
  cmd->add_option("--lcm-url", args->lcm_url,
                  std::string("LCM URL (default: $LCM_DEFAULT_URL, else ") + ort::protocol::kDefaultLcmUrl + ")");
  cmd->add_option("--channel-prefix", args->channel_prefix, "scan channel prefix (in the --namespace)")
      ->capture_default_str();
  add_namespace_flag(cmd, args->ns);
  cmd->add_option("--status-channel", args->status_channel, "the server's status channel (for --wait-for-server)")
      ->capture_default_str();
  cmd->add_option("--max-range", args->max_range, "max range sent with each scan [m]; <= 0: the server's applies")
      ->capture_default_str();
  cmd->add_option("--points-frame", args->points_frame,
                  "send points in the sensor frame with the pose, or transformed to the map frame here")
      ->check(CLI::IsMember({"sensor", "map"}))
      ->capture_default_str();
  cmd->add_option("--first", args->sel.first, "first scan index")->capture_default_str();
  cmd->add_option("--count", args->sel.count, "number of scans from --first (0: all)")->capture_default_str();
  cmd->add_option("--part", args->part,
                  "i/n: only scans whose index (from --first) % n == i, to split a set among n producers");
  cmd->add_option("--repeat", args->sel.repeat, "publish the selection this many times")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--first-seq", args->first_seq, "seq of the first scan; +1 per scan")->capture_default_str();
  cmd->add_option("--wait-for-server", args->wait_for_server_s,
                  "wait up to this many seconds for the server's status before publishing (0: don't)")
      ->capture_default_str();
  cmd->add_option("--decimate", args->decimate,
                  "send every N-th point only (e.g. to keep scans under one UDP datagram for lcm-spy)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", args->quiet, "no progress bar");
  cmd->callback([args, rate] {
    ReplayArgs a = *args;
    a.rate_given = rate->count() > 0;
    const int rc = run_replay(a);
    if (rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace ort::cli
