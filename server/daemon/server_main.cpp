// octomap-rt-server: the LCM mapping daemon.
//   octomap-rt-server -r RES --map FILE.ot [flags]      (--help lists them)
// SIGINT/SIGTERM: stop intake, apply what is queued, save, print a summary, exit 0.
// A second signal while stopping exits at once (1) without saving.
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <thread>

#include "daemon/mapping_server.h"
#include "daemon/server_cli.h"

int main(int argc, char** argv) {
  CLI::App app{"octomap-rt-server: LCM mapping daemon. Robots publish octomap_rt::scan_t on "
               "OCTOMAP_RT_SCAN_<ROBOT>; status goes to OCTOMAP_RT_STATUS (watch it with tools/octomap-rt-spy)."};
  ort::daemon::ServerFlags flags;
  ort::daemon::add_server_flags(app, flags);
  ort::daemon::ServerConfig cfg;
  try {
    app.parse(argc, argv);
    cfg = ort::daemon::to_server_config(flags);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  // Signals are taken by sigwait on the main thread only: block them before any thread starts.
  sigset_t sigs;
  sigemptyset(&sigs);
  sigaddset(&sigs, SIGINT);
  sigaddset(&sigs, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &sigs, nullptr);

  try {
    ort::daemon::MappingServer server(cfg, std::cerr);
    server.start();
    std::cerr << "octomap-rt-server: listening on " << server.lcm_url() << " for " << cfg.scan_channels
              << "; status on " << cfg.status_channel << "; pid " << ::getpid() << "\n";
    int sig = 0;
    sigwait(&sigs, &sig);
    std::cerr << "octomap-rt-server: " << (sig == SIGINT ? "SIGINT" : "SIGTERM")
              << ": stopping intake, applying queued scans, saving\n";
    std::thread([sigs] {
      int again = 0;
      sigwait(&sigs, &again);
      std::cerr << "octomap-rt-server: second signal: exiting now without saving\n";
      _exit(1);
    }).detach();
    server.stop();
    server.print_summary(std::cout);
    std::cout.flush();
  } catch (const std::exception& e) {
    std::cerr << "octomap-rt-server: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
