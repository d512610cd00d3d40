// octomap-rt: the command-line client of octomap-rt.
#include <iostream>

#include <CLI/CLI.hpp>

#include "cli/commands.h"
#include "cli/octomap_chatter.h"
#include "core/log.h"
#include "protocol/version.h"

int main(int argc, char** argv) {
  const ort::cli::OctomapChatterFilter quiet(std::cerr);  // OctoMap's "Reading octree ..." lines
  const ort::cli::OctomapStdioFilter quiet_stdio;         // its "Writing N nodes ..." lines (C stdio)
  CLI::App app{"octomap-rt: GPU-accelerated OctoMap building, and the client of octomap-rt-server"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("octomap-rt ") + OCTOMAP_RT_VERSION + " (protocol version " +
                                        std::to_string(ort::protocol::kProtocolVersion) + ")");
  ort::cli::register_build_command(app);
  ort::cli::register_replay_command(app);
  ort::cli::register_bench_command(app);
  ort::cli::register_render_command(app);
  ort::cli::register_status_command(app);
  ort::cli::register_query_command(app);
  ort::cli::register_map_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    ort::log_to(std::cerr, "octomap-rt").error(e.what());
    return 1;
  }
  return 0;
}
