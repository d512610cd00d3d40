// `octomap-rt status [--watch] [--json]`: the server's OCTOMAP_RT_STATUS, decoded and laid
// out for a terminal (client/cli/status/), once or refreshing in place.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "cli/commands.h"
#include "cli/namespace_flag.h"
#include "cli/shard_commands.h"
#include "cli/status/status_json.h"
#include "cli/status/status_text.h"
#include "core/clock.h"
#include "protocol/channels.h"
#include "protocol/lcm_url.h"
#include "protocol/version.h"

namespace ort::cli {
namespace {

struct StatusArgs {
  std::string lcm_url, channel = ort::protocol::kStatusChannel, ns;
  bool watch = false, json = false, shards = false;
  double timeout_s = 5;
  int64_t count = 0;  // --watch: stop after this many statuses (0: never)
};

// What the LCM handler leaves for the main loop: the newest status that decoded.
struct Inbox {
  std::optional<octomap_rt::server_status_t> latest;
  bool fresh = false;
  int64_t received_utime = 0, undecodable = 0;
  std::string foreign_version;  // the last undecodable status came from this protocol version
};

// Untyped, so a message that does not decode as server_status_t is counted, never thrown
// through LCM's C dispatch.
void on_status(const lcm::ReceiveBuffer* rbuf, const std::string&, Inbox* inbox) {
  octomap_rt::server_status_t s;
  bool ok = false;
  try {
    ok = s.decode(rbuf->data, 0, rbuf->data_size) >= 0;
  } catch (const std::exception&) {}
  if (!ok) {
    ++inbox->undecodable;
    inbox->foreign_version = ort::protocol::describe_foreign_version(static_cast<const uint8_t*>(rbuf->data),
                                                                     static_cast<size_t>(rbuf->data_size), s.getHash());
    return;
  }
  inbox->latest = std::move(s);
  inbox->fresh = true;
  inbox->received_utime = now_utime();
}

// Draws `text` over the previous screen: cursor home, each line cleared to its end, the
// rest of the screen cleared. Without a terminal, blocks follow each other.
void redraw(const std::string& text, bool terminal) {
  if (!terminal) {
    std::cout << text << "\n" << std::flush;
    return;
  }
  std::string out = "\x1b[H";
  size_t start = 0;
  for (size_t nl; (nl = text.find('\n', start)) != std::string::npos; start = nl + 1)
    out += text.substr(start, nl - start) + "\x1b[K\n";
  std::cout << out << "\x1b[J" << std::flush;
}

std::string watch_screen(const StatusArgs& a, const std::string& url, const Inbox& in) {
  const int64_t now = now_utime();
  std::string top = "octomap-rt status --watch: " + a.channel + " on " + url + " (Ctrl-C quits)\n";
  if (!in.latest) return top + "\nwaiting for the server's first status...\n";
  const double silent_s = double(now - in.received_utime) / 1e6;
  if (silent_s > 3)
    top += "NO STATUS FOR " + status::duration_text(silent_s) + ": the server stopped or is unreachable; last one:\n";
  return top + "\n" + status::format_status(*in.latest, now);
}

lcm::LCM& open_lcm(std::optional<lcm::LCM>& slot, const std::string& url) {
  slot.emplace(url);
  if (!slot->good()) throw std::runtime_error("cannot open LCM at " + url);
  return *slot;
}

int run_once(const StatusArgs& a, lcm::LCM& lc, const std::string& url, Inbox& in) {
  const auto deadline = SteadyClock::now() + std::chrono::duration<double>(a.timeout_s);
  while (!in.fresh && SteadyClock::now() < deadline)
    if (lc.handleTimeout(100) < 0) throw std::runtime_error("LCM receive failed on " + url);
  if (!in.fresh)
    throw std::runtime_error("no status on " + a.channel + " within " + std::to_string(int(a.timeout_s)) + " s at " +
                             url + ": is octomap-rt-server running with this LCM URL?" +
                             (in.undecodable ? " (" + std::to_string(in.undecodable) + " messages did not decode" +
                                                   (in.foreign_version.empty() ? "" : ": " + in.foreign_version) + ")"
                                             : ""));
  std::cout << (a.json ? status::status_json(*in.latest) + "\n" : status::format_status(*in.latest, now_utime()));
  return 0;
}

int run_watch(const StatusArgs& a, lcm::LCM& lc, const std::string& url, Inbox& in) {
  const bool terminal = !a.json && isatty(STDOUT_FILENO);
  if (terminal) std::cout << "\x1b[2J";
  int64_t shown = 0;
  auto last_draw = SteadyClock::now() - std::chrono::seconds(10);
  while (a.count == 0 || shown < a.count) {
    if (lc.handleTimeout(200) < 0) throw std::runtime_error("LCM receive failed on " + url);
    const bool fresh = in.fresh;
    in.fresh = false;
    if (a.json) {
      if (fresh) std::cout << status::status_json(*in.latest) << "\n" << std::flush;
    } else if (fresh || (terminal && SteadyClock::now() - last_draw > std::chrono::seconds(1))) {
      redraw(watch_screen(a, url, in), terminal);  // once a second on a terminal, so ages move
      last_draw = SteadyClock::now();
    }
    shown += fresh;
  }
  return 0;
}

// `--watch --shards`: the shards side by side, heard afresh and redrawn about once a second (a
// missing shard: every 3 s, the wait for it); the exit status of the last screen.
int run_watch_shards(const StatusArgs& a, const std::string& url, const std::string& ns) {
  const bool terminal = !a.json && isatty(STDOUT_FILENO);
  if (terminal) std::cout << "\x1b[2J";
  int rc = 0;
  for (int64_t shown = 0; a.count == 0 || shown < a.count; ++shown) {
    std::string text;
    rc = shard_status_screen(url, ns, std::min(a.timeout_s, 3.0), a.json, text);
    if (a.json)
      std::cout << text << std::flush;
    else
      redraw("octomap-rt status --watch --shards on " + url + " (Ctrl-C quits)\n\n" + text, terminal);
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  return rc;
}

int run_status(StatusArgs a) {
  if (a.shards) {
    const std::string url = protocol::lcm_url_or_default(a.lcm_url), ns = protocol::namespace_from(a.ns);
    return a.watch ? run_watch_shards(a, url, ns) : run_status_shards(url, ns, std::min(a.timeout_s, 3.0), a.json);
  }
  a.channel = protocol::in_namespace(protocol::channels_in(protocol::namespace_from(a.ns)).ns, a.channel);
  const std::string url = ort::protocol::lcm_url_or_default(a.lcm_url);
  std::optional<lcm::LCM> slot;
  lcm::LCM& lc = open_lcm(slot, url);
  Inbox inbox;
  lcm::Subscription* sub = lc.subscribeFunction(a.channel, &on_status, &inbox);
  const int rc = a.watch ? run_watch(a, lc, url, inbox) : run_once(a, lc, url, inbox);
  lc.unsubscribe(sub);
  return rc;
}

}  // namespace

void register_status_command(CLI::App& app) {
  auto args = std::make_shared<StatusArgs>();
  auto* cmd = app.add_subcommand("status", "Show octomap-rt-server's status (OCTOMAP_RT_STATUS), once or --watch");
  cmd->add_flag("-w,--watch", args->watch, "Keep showing the newest status, refreshed in place");
  cmd->add_flag("--json", args->json, "One line of JSON per status instead of text");
  cmd->add_flag("--shards", args->shards,
                "The namespace's shards (octomap-rt-server --shard) side by side, each one's newest status; "
                "says which shard is missing or late (exit status 3); with --watch, refreshed");
  cmd->add_option("--lcm-url", args->lcm_url, "LCM URL (default: $LCM_DEFAULT_URL, else the host-local udpm URL)");
  cmd->add_option("--channel", args->channel, "Status channel (in the --namespace)")->capture_default_str();
  add_namespace_flag(cmd, args->ns);
  cmd->add_option("--timeout", args->timeout_s, "Without --watch: seconds to wait for a status")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  cmd->add_option("--count", args->count, "With --watch: stop after N statuses (--shards: N screens; 0: never)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([args] {
    if (const int rc = run_status(*args); rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace ort::cli
