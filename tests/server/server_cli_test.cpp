// octomap-rt-server's command line as a user meets it: --namespace renames every channel (the
// viewer's and the reply channels' guards included) and is checked against LCM's limit at start,
// --config refuses an unknown or mistyped key and names the nearest valid one, and
// --print-config prints what a --config file would give back.
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <unistd.h>
#include "daemon/server_cli.h"

namespace ort::test {
namespace {

struct Parsed {
  std::string error;  // parse_server_flags' message, or to_server_config's
  daemon::ServerConfig config;
  std::string printed;  // effective_config
};

Parsed parse(std::vector<std::string> args) {
  CLI::App app;
  daemon::ServerFlags flags;
  daemon::add_server_flags(app, flags);
  args.insert(args.begin(), "octomap-rt-server");
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  Parsed p;
  try {
    p.error = daemon::parse_server_flags(app, static_cast<int>(argv.size()), argv.data());
    if (p.error.empty()) p.config = daemon::to_server_config(flags), p.printed = daemon::effective_config(app);
  } catch (const CLI::Error& e) {
    p.error = e.what();
  }
  return p;
}

std::string write_config(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "ort-server-cli-" + std::to_string(::getpid()) + "-" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(ServerCli, ANamespacePrefixesEveryChannel) {
  const Parsed p = parse({"-r", "0.1", "--namespace", "lab2"});
  ASSERT_EQ(p.error, "");
  const daemon::ServerConfig& c = p.config;
  for (const std::string* channel :
       {&c.status.channel, &c.scan_channels, &c.serving.request_channel, &c.serving.info_channel, &c.deltas.channel,
        &c.serving.reply_prefix, &c.octomap_raw.channel, &c.queries.points_channel, &c.queries.rays_channel,
        &c.queries.boxes_channel, &c.queries.grid_channel, &c.queries.distance_channel, &c.queries.edit_channel,
        &c.queries.grid.channel, &c.queries.scan_prefix, &c.queries.status_channel})
    EXPECT_EQ(channel->rfind("lab2_", 0), 0u) << *channel;
  EXPECT_EQ(c.octomap_raw.channel, "lab2_OCTOMAP");
  EXPECT_EQ(c.scan_channels, "lab2_OCTOMAP_RT_SCAN_.*");
  // Without one, today's names.
  const Parsed plain = parse({"-r", "0.1"});
  ASSERT_EQ(plain.error, "");
  EXPECT_EQ(plain.config.status.channel, "OCTOMAP_RT_STATUS");
  EXPECT_EQ(plain.config.ns, "");
}

TEST(ServerCli, ANamespaceThatBreaksAChannelStopsTheStart) {
  EXPECT_NE(parse({"-r", "0.1", "--namespace", "lab-2"}).error.find("letters, digits"), std::string::npos);
  EXPECT_NE(parse({"-r", "0.1", "--namespace", std::string(41, 'n')}).error.find("at most 63"), std::string::npos);
}

TEST(ServerCli, AMistypedConfigKeyIsRefusedWithTheNearestValidKey) {
  const std::string path = write_config("typo.toml", "resolution = 0.1\nsave-intervall = 5\n");
  const Parsed p = parse({"--config", path});
  EXPECT_NE(p.error.find("unknown key 'save-intervall'"), std::string::npos) << p.error;
  EXPECT_NE(p.error.find("did you mean 'save-interval'"), std::string::npos) << p.error;
  const Parsed good = parse({"--config", write_config("good.toml", "resolution = 0.2\nsave-interval = 5\n")});
  ASSERT_EQ(good.error, "");
  EXPECT_EQ(good.config.save_interval_s, 5);
  EXPECT_EQ(good.config.engine.resolution, 0.2);
}

TEST(ServerCli, ThePrintedConfigurationReadsBackAsTheSameConfiguration) {
  // A flag of each nested service config (serving, deltas, status) as well as flat ones.
  const Parsed p = parse({"-r", "0.25", "--save-interval", "7", "--namespace", "lab3", "--delta-rate", "4",
                          "--delta-exact", "--snapshot-zstd-level", "5", "--map-request-queue", "17",
                          "--chunk-interval-ms", "0.75", "--status-period", "0.5"});
  ASSERT_EQ(p.error, "");
  EXPECT_NE(p.printed.find("save-interval=7"), std::string::npos) << p.printed;
  EXPECT_NE(p.printed.find("namespace=\"lab3\""), std::string::npos) << p.printed;
  std::string text;
  for (size_t start = 0, nl; (nl = p.printed.find('\n', start)) != std::string::npos; start = nl + 1) {
    const std::string line = p.printed.substr(start, nl - start);
    if (line.rfind("print-config", 0) != 0) text += line + "\n";
  }
  const Parsed again = parse({"--config", write_config("printed.toml", text)});
  ASSERT_EQ(again.error, "") << text;
  EXPECT_EQ(again.config.engine.resolution, 0.25);
  EXPECT_EQ(again.config.save_interval_s, 7);
  EXPECT_EQ(again.config.status.channel, "lab3_OCTOMAP_RT_STATUS");
  EXPECT_EQ(again.config.status.period_s, 0.5);
  EXPECT_EQ(again.config.deltas.max_rate_hz, 4);
  EXPECT_TRUE(again.config.deltas.exact);
  EXPECT_EQ(again.config.deltas.channel, "lab3_OCTOMAP_RT_MAP_DELTA");
  EXPECT_EQ(again.config.serving.snapshots.zstd_level, 5);
  EXPECT_EQ(again.config.serving.request_queue, 17u);
  EXPECT_EQ(again.config.serving.chunk_interval_ms, 0.75);
  // Exact: the configuration read back prints the same text again, key for key.
  EXPECT_EQ(again.printed, p.printed);
}

}  // namespace
}  // namespace ort::test

namespace ort::test {
namespace {

// --shard i/N: the hash rule, the shard's own channels in NS_SHARD<i>, scans and status in NS;
// --shard-box: one box per shard in metres, overlaps and gaps refused at start.
TEST(ServerCli, AShardHearsTheNamespacesScansAndServesOnItsOwnChannels) {
  const Parsed p = parse({"-r", "0.1", "--namespace", "lab2", "--shard", "1/3"});
  ASSERT_EQ(p.error, "");
  const daemon::ServerConfig& c = p.config;
  EXPECT_EQ(c.shard.rule, protocol::ShardRule::kHash);
  EXPECT_EQ(c.shard.index, 1u);
  EXPECT_EQ(c.shard.count, 3u);
  EXPECT_EQ(c.scan_channels, "lab2_OCTOMAP_RT_SCAN_.*");
  EXPECT_EQ(c.status.channel, "lab2_OCTOMAP_RT_STATUS");
  EXPECT_EQ(c.queries.status_channel, "lab2_OCTOMAP_RT_STATUS");
  EXPECT_EQ(c.serving.request_channel, "lab2_SHARD1_OCTOMAP_RT_MAP_REQUEST");
  EXPECT_EQ(c.serving.reply_prefix, "lab2_SHARD1_OCTOMAP_RT_MAP_REPLY_");
  EXPECT_EQ(c.queries.points_channel, "lab2_SHARD1_OCTOMAP_RT_QUERY");
  EXPECT_EQ(c.octomap_raw.channel, "lab2_SHARD1_OCTOMAP");
  const std::string west = "-inf,-inf,-inf:0,inf,inf", east = "0,-inf,-inf:inf,inf,inf";
  const Parsed boxes = parse({"-r", "0.1", "--shard", "0/2", "--shard-box", west, "--shard-box", east});
  ASSERT_EQ(boxes.error, "");
  EXPECT_EQ(boxes.config.shard.rule, protocol::ShardRule::kBoxes);
  EXPECT_EQ(boxes.config.shard.boxes.size(), 2u);
  const Parsed gap =
      parse({"-r", "0.1", "--shard", "0/2", "--shard-box", west, "--shard-box", "7,-inf,-inf:inf,inf,inf"});
  EXPECT_NE(gap.error.find("the boxes leave a gap"), std::string::npos) << gap.error;
  const Parsed overlap =
      parse({"-r", "0.1", "--shard", "0/2", "--shard-box", west, "--shard-box", "-7,-inf,-inf:inf,inf,inf"});
  EXPECT_NE(overlap.error.find("boxes 0 and 1 overlap"), std::string::npos) << overlap.error;
  EXPECT_NE(parse({"-r", "0.1", "--shard", "0/2", "--shard-box", west}).error.find("1 boxes for 2 shards"),
            std::string::npos);
  EXPECT_NE(parse({"-r", "0.1", "--shard", "3/3"}).error.find("is not i/N"), std::string::npos);
  EXPECT_NE(parse({"-r", "0.1", "--shard", "0/2", "--shard-box", "1,2,3:0,5,6", "--shard-box", east})
                .error.find("is not X0,Y0,Z0:X1,Y1,Z1"),
            std::string::npos);
  EXPECT_NE(parse({"-r", "0.1", "--shard-box", west}).error.find("needs --shard"), std::string::npos);
}

}  // namespace
}  // namespace ort::test
