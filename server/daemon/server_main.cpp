// octomap-rt-server: the LCM mapping daemon.
//   octomap-rt-server -r RES --map FILE.ot [flags]      (--help lists them)
//
// Signals (docs/RELIABILITY.md, "Shutdown"):
//   SIGTERM / SIGINT  stop intake, apply queued scans for at most --drain-timeout seconds
//                     (the rest are dropped: "left at shutdown"), save, print the summary.
//                     Exit 0, or 1 when the final save failed. A repeat during the drain is
//                     idempotent: it is logged and changes nothing.
//   SIGQUIT, or SIGTERM/SIGINT again after the drain deadline
//                     exit at once (2), after saving the map as applied if a save can be made
//                     (3 when it cannot).
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <thread>

#include "core/clock.h"
#include "core/log.h"
#include "daemon/mapping_server.h"
#include "daemon/server_cli.h"
#include "protocol/channels.h"
#include "protocol/version.h"

namespace {

const char* signal_name(int sig) { return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "SIGQUIT"; }

// The immediate exit: no drain, but the map as applied is saved when a save can be made
// (an orderly save already running is waited for, not cut short).
[[noreturn]] void exit_now(ort::daemon::MappingServer& server, int sig, const ort::Log& log) {
  log.warning(ort::text(signal_name(sig), ": exiting now; saving the map as applied"));
  int code = 2;
  try {
    server.save(false);
  } catch (const std::exception& e) {
    log.error(ort::text("the map could not be saved: ", e.what()));
    code = 3;
  }
  std::_Exit(code);  // the log's lines are flushed as they are written
}

// Takes every later signal while the orderly stop runs (detached: it ends with the process).
void watch_signals(ort::daemon::MappingServer& server, sigset_t sigs, ort::SteadyClock::time_point drain_deadline,
                   ort::Log log) {
  std::thread([&server, sigs, drain_deadline, log] {
    for (;;) {
      int sig = 0;
      if (sigwait(&sigs, &sig) != 0) continue;
      const double left = std::chrono::duration<double>(drain_deadline - ort::SteadyClock::now()).count();
      if (sig == SIGQUIT || left <= 0) exit_now(server, sig, log);
      char line[200];
      std::snprintf(line, sizeof line,
                    "%s: already stopping; queued scans are applied for %.1f s more, then the map is saved (SIGQUIT "
                    "exits at once)",
                    signal_name(sig), left);
      log.info(line);
    }
  }).detach();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{std::string("octomap-rt-server: LCM mapping daemon. Robots publish octomap_rt::scan_t on ") +
               ort::protocol::kScanChannelPrefix + "<ROBOT>; status goes to " + ort::protocol::kStatusChannel +
               " (watch it with tools/octomap-rt-spy)."};
  ort::daemon::ServerFlags flags;
  ort::daemon::add_server_flags(app, flags);
  app.set_version_flag("--version", std::string("octomap-rt-server ") + OCTOMAP_RT_VERSION + " (protocol version " +
                                        std::to_string(ort::protocol::kProtocolVersion) + ")");
  ort::daemon::ServerConfig cfg;
  try {
    if (const std::string bad = ort::daemon::parse_server_flags(app, argc, argv); !bad.empty()) {
      std::cerr << "octomap-rt-server: " << bad << "\n";
      return 2;
    }
    cfg = ort::daemon::to_server_config(flags);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (flags.print_config) {
    std::cout << ort::daemon::effective_config(app);
    return 0;
  }

  // Signals are taken by sigwait only: block them before any thread starts.
  sigset_t sigs;
  sigemptyset(&sigs);
  sigaddset(&sigs, SIGINT);
  sigaddset(&sigs, SIGTERM);
  sigaddset(&sigs, SIGQUIT);
  pthread_sigmask(SIG_BLOCK, &sigs, nullptr);

  // Every message of the daemon's threads goes through this one sink (whole lines, stderr).
  const ort::Log log = ort::log_to(std::cerr, "octomap-rt-server");
  try {
    ort::daemon::MappingServer server(cfg, log);
    server.start();
    log.info(ort::text("listening on ", server.lcm_url(), " for ", cfg.scan_channels, "; status on ",
                       cfg.status.channel, "; pid ", ::getpid()));
    int sig = 0;
    while (sigwait(&sigs, &sig) != 0) {}
    if (sig == SIGQUIT) exit_now(server, sig, log);
    log.info(ort::text(signal_name(sig), ": stopping intake, applying queued scans for at most ", cfg.drain_timeout_s,
                       " s, saving"));
    watch_signals(server, sigs,
                  ort::SteadyClock::now() + std::chrono::duration_cast<ort::SteadyClock::duration>(
                                                std::chrono::duration<double>(cfg.drain_timeout_s)),
                  log);
    const bool saved = server.stop();
    server.print_summary(std::cout);
    std::cout.flush();
    if (!saved) {
      log.error("the final save failed (see the summary); exit status 1");
      return 1;
    }
  } catch (const std::exception& e) {
    log.error(e.what());
    return 1;
  }
  return 0;
}
