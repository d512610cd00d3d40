// `octomap-rt map clear-box|reset` (next to map get/info/watch/diff): edit a running server's map (applied in order with the
// scans; the server must run with --control-token and the request carry it). clear-box --to free changes known voxels
// only unless --include-unknown.
#include <unistd.h>

#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/namespace_flag.h"
#include "cli/shard_commands.h"
#include "core/log.h"
#include "octomap_rt/map_edit_t.hpp"
#include "protocol/lcm_url.h"
#include "query_client/query_args.h"
#include "query_client/query_client.h"
#include "query_client/query_json.h"

namespace ort::cli {
namespace {

struct EditArgs {
  std::string lcm_url, token, box, to = "free", ns;
  double timeout_s = 10;
  bool json = false;
  bool include_unknown = false;
  bool shards = false;  // a shard set: the edit goes to the shards owning its box
};

void run_edit(const EditArgs& a, int8_t op) {
  client::Box b{};
  if (op != octomap_rt::map_edit_t::OP_RESET) b = client::parse_box(a.box);
  const int8_t flags = a.include_unknown ? octomap_rt::map_edit_t::FLAG_INCLUDE_UNKNOWN : 0;
  bool partial = false;
  octomap_rt::map_edit_ack_t ack;
  if (a.shards) {
    if (a.include_unknown) throw CLI::ValidationError("--include-unknown", "every shard refuses it (--shards)");
    const std::string url = ort::protocol::lcm_url_or_default(a.lcm_url), ns = protocol::namespace_from(a.ns);
    const client::ShardRoster roster = find_shards_for_query(url, ns, a.timeout_s);
    client::ShardQueries q(url, "cli-" + std::to_string(::getpid()),
                           std::chrono::milliseconds(static_cast<int64_t>(a.timeout_s * 1000)), ns, *roster.set(),
                           roster.resolution());
    const auto routed = q.edit(op, b, a.token, flags);
    partial = say_partial(routed.shards);
    ack = routed.reply;
  } else {
    client::QueryClient c(ort::protocol::lcm_url_or_default(a.lcm_url), "cli-" + std::to_string(::getpid()),
                          std::chrono::milliseconds(static_cast<int64_t>(a.timeout_s * 1000)),
                          protocol::namespace_from(a.ns));
    ack = c.edit(op, b, a.token, flags);
  }
  if (a.json) client::write_edit_json(std::cout, ack);
  if (ack.status != 0) {
    log_to(std::cerr, "octomap-rt map").error(std::string(client::status_name(ack.status)) + ": " + ack.error);
    std::exit(partial ? 3 : 2);
  }
  if (!a.json) std::cout << "applied; the map holds it from map state " << ack.snapshot_id << "\n";
}

void add_common(CLI::App* cmd, EditArgs& a) {
  cmd->add_option("--token", a.token, "the server's --control-token (signs the edit; never sent)")->required();
  cmd->add_option("--lcm-url", a.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL, else the host-local udpm URL)");
  add_namespace_flag(cmd, a.ns);
  cmd->add_option("--timeout", a.timeout_s, "seconds to wait for the acknowledgement")->capture_default_str();
  cmd->add_flag("--json", a.json, "one JSON document on stdout");
  cmd->add_flag("--shards", a.shards,
                "the namespace is a shard set: send the edit to the shards owning a region of its box (every "
                "shard for reset); exit status 3 when one did not apply it");
}

}  // namespace

void add_map_edit_commands(CLI::App* cmd) {
  auto clear = std::make_shared<EditArgs>();
  auto* c = cmd->add_subcommand("clear-box",
                                "set the known voxels of a box free, or every voxel of it unknown (the box only: "
                                "leaves across its border are split there)");
  add_common(c, *clear);
  c->add_option("box", clear->box, "MINX,MINY,MINZ:MAXX,MAXY,MAXZ [m]")->required();
  c->add_option("--to", clear->to, "free or unknown")->check(CLI::IsMember({"free", "unknown"}))->capture_default_str();
  c->add_flag("--include-unknown", clear->include_unknown,
              "with --to free: mark the box's never-seen voxels free too (planners trust free space: only for "
              "space known to be empty)");
  c->callback([clear] {
    run_edit(*clear, clear->to == "free" ? octomap_rt::map_edit_t::OP_CLEAR_TO_FREE
                                         : octomap_rt::map_edit_t::OP_CLEAR_TO_UNKNOWN);
  });
  auto reset = std::make_shared<EditArgs>();
  auto* r = cmd->add_subcommand("reset", "empty the whole map");
  add_common(r, *reset);
  r->callback([reset] { run_edit(*reset, octomap_rt::map_edit_t::OP_RESET); });
}

}  // namespace ort::cli
