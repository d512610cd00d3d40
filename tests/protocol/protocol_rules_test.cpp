// The rules of the protocol's home: channel names in a namespace (and LCM's length limit),
// the id rules both services share, and how a client names the version of a server whose
// message types differ from its own.
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "octomap_rt/map_chunk_t.hpp"
#include "octomap_rt/map_info_t.hpp"
#include "octomap_rt/map_request_t.hpp"
#include "octomap_rt/server_status_t.hpp"
#include "protocol/channels.h"
#include "protocol/ids.h"
#include "protocol/inbound_checks.h"
#include "protocol/map_request_rules.h"
#include "protocol/version.h"

namespace ort::test {
namespace {

using namespace ort::protocol;

TEST(ProtocolRules, NoNamespaceMeansTodaysNames) {
  const Channels c = channels_in("");
  EXPECT_EQ(c.status, kStatusChannel);
  EXPECT_EQ(c.scan_regex(), std::string(kScanChannelPrefix) + ".*");
  EXPECT_EQ(c.octomap_raw, "OCTOMAP");
  EXPECT_EQ(c.map_reply_prefix, kMapReplyPrefix);
}

TEST(ProtocolRules, ANamespacePrefixesEveryChannelItsViewerChannelIncluded) {
  const Channels c = channels_in("lab2");
  for (const std::string* name : {&c.scan_prefix, &c.status, &c.map_request, &c.map_info, &c.map_delta,
                                  &c.map_reply_prefix, &c.query_points, &c.query_rays, &c.query_boxes, &c.query_grid,
                                  &c.query_distance, &c.map_edit, &c.query_reply_prefix, &c.grid, &c.octomap_raw})
    EXPECT_EQ(name->rfind("lab2_", 0), 0u) << *name;
  EXPECT_EQ(c.octomap_raw, "lab2_OCTOMAP");
  EXPECT_EQ(c.status, "lab2_OCTOMAP_RT_STATUS");
  EXPECT_EQ(reply_channel_for("planner-1", c.map_reply_prefix), "lab2_OCTOMAP_RT_MAP_REPLY_PLANNER_1");
}

TEST(ProtocolRules, NamespacesAreCheckedAtStart) {
  EXPECT_THROW(channels_in("lab-2"), std::invalid_argument);  // '-' is not allowed
  EXPECT_THROW(channels_in("a b"), std::invalid_argument);
  // 63 characters in all: OCTOMAP_RT_MAP_REPLY_ (21) + one id character leaves 41 for NS_, and
  // OCTOMAP_RT_MAP_REQUEST (22) as many.
  EXPECT_NO_THROW(channels_in(std::string(40, 'n')));
  try {
    channels_in(std::string(41, 'n'));
    FAIL() << "a namespace that makes a name longer than LCM takes was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("at most 63"), std::string::npos) << e.what();
  }
  EXPECT_EQ(check_channel_length(std::string(63, 'C')), "");
  EXPECT_NE(check_channel_length(std::string(64, 'C')), "");
}

// A server in a namespace answers map requests whose reply channel is in that namespace (a
// namespaced client's), and only those.
TEST(ProtocolRules, MapRequestsAreAnsweredOnTheServersNamespacesReplyChannels) {
  octomap_rt::map_request_t r{};
  r.client_id = "planner";
  r.format = octomap_rt::map_chunk_t::FORMAT_OCTOMAP_FULL;
  r.reply_channel = channels_in("lab2").map_reply_prefix + "PLANNER";
  EXPECT_EQ(check_map_request(r, channels_in("lab2").map_reply_prefix), RequestRefusal::kNone);
  EXPECT_EQ(check_map_request(r, kMapReplyPrefix), RequestRefusal::kBadReplyChannel);
  r.reply_channel = std::string(kMapReplyPrefix) + "PLANNER";
  EXPECT_EQ(check_map_request(r, kMapReplyPrefix), RequestRefusal::kNone);
  EXPECT_FALSE(can_reply(r, channels_in("lab2").map_reply_prefix));
}

TEST(ProtocolRules, OneClientIdRuleForMapRequestsAndQueries) {
  EXPECT_TRUE(valid_name("planner-1_a"));
  EXPECT_FALSE(valid_name(""));
  EXPECT_FALSE(valid_name("a.b"));
  EXPECT_FALSE(valid_name(std::string(64, 'a')));
  EXPECT_EQ(check_client_id("planner-1"), "");
  EXPECT_NE(check_client_id("a.b"), "");
  EXPECT_EQ(check_reply_channel("OCTOMAP_RT_REPLY_X"), "");
  EXPECT_NE(check_reply_channel(std::string(64, 'R')), "");
  EXPECT_NE(check_reply_channel("has space"), "");
  EXPECT_TRUE(same_robot_id("Husky-3", "HUSKY-3"));
  EXPECT_EQ(channel_suffix("husky-3"), "HUSKY_3");
}

template <class T>
std::vector<uint8_t> encode(const T& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

TEST(ProtocolRules, ProtocolVersionIsTheFirstFieldAndNamedWhenTypesDiffer) {
  octomap_rt::server_status_t s{};
  s.protocol_version = kProtocolVersion;
  auto b = encode(s);
  EXPECT_EQ(describe_foreign_version(b.data(), b.size(), octomap_rt::server_status_t::getHash()), "");
  // A server of a later version: another fingerprint, its version at bytes 8..11.
  b[0] ^= 0x5a;
  b[kVersionOffset + 3] = static_cast<uint8_t>(kProtocolVersion + 1);
  const std::string later = describe_foreign_version(b.data(), b.size(), octomap_rt::server_status_t::getHash());
  EXPECT_NE(later.find("protocol version " + std::to_string(kProtocolVersion + 1)), std::string::npos) << later;
  EXPECT_NE(later.find("this program version " + std::to_string(kProtocolVersion)), std::string::npos) << later;
  // Version 1 had no field: bytes 8..11 are the high half of a microsecond timestamp.
  octomap_rt::map_info_t old{};
  old.protocol_version = 1'800'000'000;  // what utime's high half reads as today
  auto o = encode(old);
  o[0] ^= 0x5a;
  EXPECT_NE(
      describe_foreign_version(o.data(), o.size(), octomap_rt::map_info_t::getHash()).find("older than version 2"),
      std::string::npos);
  // The map_info_t count sits where inbound_checks says, after the version.
  octomap_rt::map_info_t m{};
  m.num_producers = 1;
  m.producer_last_seq = {7};
  m.producer_id = {"a"};
  const auto mb = encode(m);
  octomap_rt::map_info_t out{};
  EXPECT_TRUE(check_info(mb.data(), mb.size(), out).ok());
}

}  // namespace
}  // namespace ort::test
