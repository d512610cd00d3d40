// octomap-rt-loadtest: a load test of octomap-rt-server in a private network namespace.
//   octomap-rt-loadtest --producers 8 --rate 10 --duration 30 --points 100000 -- -r 0.1 --backend cpu
// Exit status: 0 when every scan is accounted for and the server stopped cleanly, 1 otherwise.
#include <iostream>

#include <CLI/CLI.hpp>

#include "load_test.h"
#include "protocol/limits.h"

int main(int argc, char** argv) {
  CLI::App app{
      "octomap-rt-loadtest: N producers at a rate for a bounded time against octomap-rt-server, in a "
      "private network namespace; reports scans accounted, peak memory, latency p99 and drops"};
  ort::cli::LoadTestConfig cfg;
  cfg.server = OCTOMAP_RT_SERVER;
  std::vector<std::string> server_args;
  app.add_option("--producers", cfg.producers, "producers (robots), each on its own channel")->capture_default_str();
  app.add_option("--rate", cfg.rate_hz, "scans per second per producer")
      ->check(CLI::Range(0.01, 1000.0))
      ->capture_default_str();
  app.add_option("--duration", cfg.duration_s, "seconds of publishing")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  app.add_option("--points", cfg.points, "points per scan")
      ->check(CLI::Range(uint64_t{1}, ort::protocol::kDefaultMaxScanPoints))
      ->capture_default_str();
  app.add_option("--settle", cfg.settle_s, "seconds to wait afterwards for the queue to empty")->capture_default_str();
  app.add_option("--server", cfg.server, "octomap-rt-server program")->capture_default_str();
  app.add_option("--log", cfg.log_path, "the server's log file")->capture_default_str();
  app.add_option("--scene", cfg.scene,
                 "what the robots scan, going round it: synthetic, a preset (fr079-real, ...) or a .graph file")
      ->capture_default_str();
  app.add_option("--data", cfg.data_dir, "where fr079-real finds octomap_share/geb079.bt");
  app.add_option("--series", cfg.series_path,
                 "CSV of the server's memory and latency at every status message (the soak benchmark's series)");
  app.add_option("server-args", server_args, "after --: the server's flags (default: -r 0.1)");
  CLI11_PARSE(app, argc, argv);
  if (!server_args.empty()) cfg.server_args = server_args;
  if (const std::string why = ort::cli::enter_private_network(); !why.empty()) {
    std::cerr << "octomap-rt-loadtest: cannot make a private network namespace: " << why << "\n";
    return 2;
  }
  try {
    const ort::cli::LoadReport r = ort::cli::run_load_test(cfg);
    ort::cli::print_load_report(std::cout, cfg, r);
    return r.accounted() && r.server_exit == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "octomap-rt-loadtest: error: " << e.what() << "\n";
    return 1;
  }
}
