// `--namespace NS` on every subcommand that talks to octomap-rt-server: the server's namespace
// (protocol/channels.h: every channel is NS_ + its name); default $OCTOMAP_RT_NAMESPACE, else
// none.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "protocol/channels.h"

namespace ort::cli {

inline void add_namespace_flag(CLI::App* cmd, std::string& ns) {
  cmd->add_option("--namespace", ns,
                  std::string("the server's namespace (its --namespace): every channel is NS_ + its name; default: $") +
                      protocol::kNamespaceEnv + ", else none");
}

}  // namespace ort::cli
