#include "cli/shard_commands.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli/map_commands.h"
#include "cli/status/status_text.h"
#include "core/clock.h"
#include "core/log.h"
#include "protocol/lcm_url.h"
#include "protocol/shards/shard_wire.h"
#include "shard_client/shard_snapshot.h"

namespace ort::cli {
namespace {

// A shard whose last status is older than this is late (statuses come at 1 Hz).
constexpr double kLateAfterS = 3.0;

std::string set_text(const client::ShardRoster& r) {
  const protocol::ShardSet& s = *r.set();
  if (!s.sharded()) return "not sharded (one server maps the whole map)";
  return std::string(protocol::to_string(s.rule)) + " rule, " + std::to_string(s.count) + " shards, regions at depth " +
         std::to_string(s.region_depth) + ", resolution " + std::to_string(r.resolution()) + " m";
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) >= 0x20) out += c;
  }
  return out + "\"";
}

}  // namespace

int run_get_shards(const MapArgs& a, const std::string& out_path, bool partial) {
  const bool bt = out_path.size() > 3 && out_path.compare(out_path.size() - 3, 3, ".bt") == 0;
  const bool ot = out_path.size() > 3 && out_path.compare(out_path.size() - 3, 3, ".ot") == 0;
  if (!bt && !ot) throw std::runtime_error("-o must end in .bt or .ot");
  const std::string url = protocol::lcm_url_or_default(a.lcm_url), ns = protocol::namespace_from(a.ns);
  const client::ShardRoster roster = client::discover_shards(url, ns, std::min(a.timeout_s, 5.0));
  if (!roster.set()) throw std::runtime_error("no server status in namespace '" + ns + "' (is a shard running?)");
  const client::MergedMap m = client::fetch_merged_map(url, ns, roster, a.timeout_s);
  int64_t newest = 0;
  for (const auto& p : m.parts) newest = std::max(newest, p.num_scans);
  std::string late;
  for (const auto& p : m.parts)
    if (p.fetched && p.num_scans < newest)
      late += (late.empty() ? "" : "; ") + std::string("shard ") + std::to_string(p.index) + " is " +
              std::to_string(newest - p.num_scans) + " scans behind the newest shard";
  const bool write = m.tree && (!m.partial || partial);
  if (write) {
    std::ofstream f(out_path, std::ios::binary);
    if (bt)
      m.tree->writeBinary(f);  // OctoMap's .bt of record: max likelihood, pruned
    else
      m.tree->write(f);
    if (!f) throw std::runtime_error("cannot write '" + out_path + "'");
  }
  if (a.json) {
    std::cout << "{\"shard_set\": " << json_string(set_text(roster))
              << ", \"partial\": " << (m.partial ? "true" : "false") << ", \"shortfall\": " << json_string(m.shortfall)
              << ", \"late\": " << json_string(late) << ", \"file\": " << json_string(write ? out_path : "")
              << ", \"nodes\": " << (m.tree ? m.tree->size() : 0) << ", \"shards\": [";
    for (size_t i = 0; i < m.parts.size(); ++i) {
      const auto& p = m.parts[i];
      std::cout << (i ? ", " : "") << "{\"index\": " << p.index << ", \"fetched\": " << (p.fetched ? "true" : "false")
                << ", \"snapshot_id\": " << p.snapshot_id << ", \"scans\": " << p.num_scans
                << ", \"epoch\": " << p.epoch << ", \"bytes\": " << p.bytes << ", \"seconds\": " << p.seconds
                << ", \"error\": " << json_string(p.error) << "}";
    }
    std::cout << "]}\n";
  } else {
    std::printf("shard set of namespace '%s': %s\n", ns.c_str(), set_text(roster).c_str());
    for (const auto& p : m.parts) {
      if (p.fetched)
        std::printf("  shard %u: snapshot %lld (%lld scans, epoch %lld), %lld bytes .ot, %.3f s\n", p.index,
                    (long long)p.snapshot_id, (long long)p.num_scans, (long long)p.epoch, (long long)p.bytes,
                    p.seconds);
      else
        std::printf("  shard %u: MISSING: %s\n", p.index, p.error.c_str());
    }
    if (write)
      std::printf("merged map: %zu nodes -> %s%s\n", m.tree->size(), out_path.c_str(), m.partial ? " (PARTIAL)" : "");
  }
  const Log log = log_to(std::cerr, "octomap-rt map get");
  if (!late.empty()) log.warning("LATE: " + late);
  if (m.partial)
    log.warning((write ? "PARTIAL map written: " : "no map written (--partial writes one): ") + m.shortfall);
  return m.partial ? (write ? 3 : 1) : 0;
}

int run_status_shards(const std::string& url, const std::string& ns, double timeout_s, bool json) {
  std::string text;
  const int rc = shard_status_screen(url, ns, timeout_s, json, text);
  std::cout << text;
  return rc;
}

int shard_status_screen(const std::string& url, const std::string& ns, double timeout_s, bool json, std::string& text) {
  const client::ShardRoster roster = client::discover_shards(url, ns, timeout_s);
  if (!roster.set())
    throw std::runtime_error("no status in namespace '" + ns + "' within " + std::to_string(timeout_s) + " s");
  const int64_t now = now_utime();
  const std::string shortfall = roster.shortfall(now, kLateAfterS);
  std::ostringstream out;
  if (json) {
    out << "{\"shard_set\": " << json_string(set_text(roster)) << ", \"count\": " << roster.set()->count
        << ", \"shortfall\": " << json_string(shortfall) << ", \"shards\": [";
    bool first = true;
    for (const auto& [i, m] : roster.members()) {
      const auto& s = m.status;
      out << (first ? "" : ", ") << "{\"index\": " << i << ", \"server_id\": " << json_string(s.server_id)
          << ", \"state\": " << json_string(status::state_name(s.state)) << ", \"map_epoch\": " << s.map_epoch
          << ", \"map_version\": " << s.map_version << ", \"scans_applied\": " << s.scans_applied
          << ", \"nodes\": " << s.num_nodes << ", \"memory_bytes\": " << s.memory_bytes
          << ", \"scans_per_s\": " << s.scans_per_s << ", \"octree_ms_p99\": " << s.octree_ms_p99
          << ", \"end_to_end_ms_p99\": " << s.end_to_end_ms_p99
          << ", \"age_s\": " << double(now - m.received_utime) / 1e6 << "}";
      first = false;
    }
    out << "]}\n";
  } else {
    out << "shard set of namespace '" << ns << "': " << set_text(roster) << "\n\n";
    char line[256];
    std::snprintf(line, sizeof line, "%-5s %-28s %-9s %11s %9s %12s %10s %8s %10s %9s\n", "shard", "server", "state",
                  "map version", "applied", "nodes", "memory", "scans/s", "e2e p99ms", "status");
    out << line;
    for (uint32_t i = 0; i < roster.set()->count; ++i) {
      const auto it = roster.members().find(i);
      if (it == roster.members().end()) {
        std::snprintf(line, sizeof line, "%-5u MISSING: no status within %.0f s\n", i, timeout_s);
        out << line;
        continue;
      }
      const auto& s = it->second.status;
      std::snprintf(line, sizeof line, "%-5u %-28.28s %-9s %11lld %9lld %12s %10s %8.1f %10.1f %7.1f s\n", i,
                    s.server_id.c_str(), status::state_name(s.state).c_str(), (long long)s.map_version,
                    (long long)s.scans_applied, status::with_commas(s.num_nodes).c_str(),
                    status::bytes_text(s.memory_bytes).c_str(), s.scans_per_s, s.end_to_end_ms_p99,
                    double(now - it->second.received_utime) / 1e6);
      out << line;
    }
    if (!shortfall.empty()) out << "\nPARTIAL: " << shortfall << "\n";
    for (const auto& [why, n] : roster.refused()) out << "statuses refused (" << why << "): " << n << "\n";
  }
  text = out.str();
  return shortfall.empty() ? 0 : 3;
}

client::ShardRoster find_shards_for_query(const std::string& url, const std::string& ns, double timeout_s) {
  client::ShardRoster roster = client::discover_shards(url, ns, std::min(timeout_s, 3.0));
  if (!roster.set()) throw std::runtime_error("no server status in namespace '" + ns + "': no shard to ask");
  if (const std::string s = roster.shortfall(now_utime(), kLateAfterS); !s.empty())
    log_to(std::cerr, "octomap-rt query").warning(s);
  return roster;
}

bool say_partial(const client::ShardAnswer& a) {
  if (!a.partial()) return false;
  log_to(std::cerr, "octomap-rt query").warning("PARTIAL answer: " + a.shortfall());
  return true;
}

}  // namespace ort::cli
