// Each subcommand of `octomap-rt` lives in its own file and registers itself here.
#pragma once

#include <CLI/CLI.hpp>

namespace ort::cli {

void register_build_command(CLI::App& app);
void register_replay_command(CLI::App& app);
void register_bench_command(CLI::App& app);
void register_render_command(CLI::App& app);
void register_status_command(CLI::App& app);
void register_query_command(CLI::App& app);
void add_map_edit_commands(CLI::App* map_command);
void register_map_command(CLI::App& app);

}  // namespace ort::cli
