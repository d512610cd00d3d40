// The MAC of map edits (protocol/edit_mac.h): the canonical bytes and MAC of the test vector in
// docs/PROTOCOL.md (computed independently with Python's hmac), and that every field and the
// channel change the MAC.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "protocol/edit_mac.h"

namespace ort::test {
namespace {

const std::string kToken = "correct horse battery staple";

octomap_rt::map_edit_t vector_edit() {
  octomap_rt::map_edit_t e{};
  e.utime = 1700000000000000;
  e.request_id = 42;
  e.nonce = 0x0123456789abcdef;
  e.op = 1, e.flags = 1;
  const double lo[3] = {-1.5, -2, 0}, hi[3] = {3.25, 4, 2.5};
  std::copy(lo, lo + 3, e.box_min), std::copy(hi, hi + 3, e.box_max);
  e.client_id = "op-laptop";
  e.reply_channel = "OCTOMAP_RT_QUERY_REPLY_op-laptop";
  return e;
}

template <class Bytes>
std::string hex(const Bytes& b) {
  std::string out;
  char two[3];
  for (auto c : b) std::snprintf(two, sizeof two, "%02x", static_cast<unsigned>(static_cast<uint8_t>(c))), out += two;
  return out;
}

TEST(EditMac, TheTestVectorOfTheProtocol) {
  const auto e = vector_edit();
  const std::vector<uint8_t> input = protocol::edit_mac_input("OCTOMAP_RT_MAP_EDIT", e);
  EXPECT_EQ(input.size(), 171u);
  EXPECT_EQ(hex(input),
            "6f63746f6d61702d7274206d61705f656469745f7420763100000000134f43544f4d41505f52545f4d41505f4544495400060a241"
            "81e4000000000000000002a0123456789abcdef0101bff8000000000000c000000000000000000000000000000040"
            "0a00000000000040100000000000004004000000000000000000096f702d6c6170746f70000000204f43544f4d41505f52545f51"
            "554552595f5245504c595f6f702d6c6170746f70");
  EXPECT_EQ(hex(protocol::edit_mac(kToken, "OCTOMAP_RT_MAP_EDIT", e)),
            "43c438d9f28edc9bfd49387db5cc06d0920214256168c2abff07736c474282b9");
}

TEST(EditMac, EveryFieldAndTheChannelAreCovered) {
  auto signed_edit = vector_edit();
  protocol::sign_edit(signed_edit, kToken, "OCTOMAP_RT_MAP_EDIT");
  ASSERT_TRUE(protocol::edit_mac_matches(kToken, "OCTOMAP_RT_MAP_EDIT", signed_edit));
  EXPECT_FALSE(protocol::edit_mac_matches(kToken, "NS_OCTOMAP_RT_MAP_EDIT", signed_edit));
  EXPECT_FALSE(protocol::edit_mac_matches(kToken + "!", "OCTOMAP_RT_MAP_EDIT", signed_edit));
  const std::vector<void (*)(octomap_rt::map_edit_t&)> changes = {
      [](octomap_rt::map_edit_t& e) { e.utime++; },
      [](octomap_rt::map_edit_t& e) { e.request_id++; },
      [](octomap_rt::map_edit_t& e) { e.nonce ^= 1; },
      [](octomap_rt::map_edit_t& e) { e.op = 2; },
      [](octomap_rt::map_edit_t& e) { e.flags = 0; },
      [](octomap_rt::map_edit_t& e) { e.box_min[2] = -0.0; },  // the bits, not the value
      [](octomap_rt::map_edit_t& e) { e.box_max[0] = 3.2500000000000004; },
      [](octomap_rt::map_edit_t& e) { e.client_id = "op-laptoP"; },
      [](octomap_rt::map_edit_t& e) { e.reply_channel += "X"; },
      // A byte moved from one string to the next: the lengths keep them apart.
      [](octomap_rt::map_edit_t& e) { e.client_id = "op-lapto", e.reply_channel = "p" + e.reply_channel; },
  };
  for (size_t i = 0; i < changes.size(); ++i) {
    auto e = signed_edit;
    changes[i](e);
    EXPECT_FALSE(protocol::edit_mac_matches(kToken, "OCTOMAP_RT_MAP_EDIT", e)) << "change " << i;
  }
  EXPECT_NE(protocol::random_edit_nonce(), protocol::random_edit_nonce());
}

}  // namespace
}  // namespace ort::test
