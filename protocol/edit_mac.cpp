#include "protocol/edit_mac.h"

#include <sodium.h>

#include <cstring>
#include <stdexcept>

namespace ort::protocol {
namespace {

constexpr char kDomain[] = "octomap-rt map_edit_t v1";  // and its NUL: 25 bytes

void put_u64(std::vector<uint8_t>& out, uint64_t v) {
  for (int shift = 56; shift >= 0; shift -= 8) out.push_back(static_cast<uint8_t>(v >> shift));
}

void put_string(std::vector<uint8_t>& out, std::string_view s) {
  const auto n = static_cast<uint32_t>(s.size());
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<uint8_t>(n >> shift));
  out.insert(out.end(), s.begin(), s.end());
}

void put_double(std::vector<uint8_t>& out, double d) {
  uint64_t bits = 0;
  std::memcpy(&bits, &d, sizeof bits);
  put_u64(out, bits);
}

void ensure_sodium() {
  if (sodium_init() < 0) throw std::runtime_error("libsodium failed to initialise");
}

}  // namespace

std::vector<uint8_t> edit_mac_input(std::string_view channel, const octomap_rt::map_edit_t& e) {
  std::vector<uint8_t> out(kDomain, kDomain + sizeof kDomain);
  put_string(out, channel);
  put_u64(out, static_cast<uint64_t>(e.utime));
  put_u64(out, static_cast<uint64_t>(e.request_id));
  put_u64(out, static_cast<uint64_t>(e.nonce));
  out.push_back(static_cast<uint8_t>(e.op));
  out.push_back(static_cast<uint8_t>(e.flags));
  for (double d : e.box_min) put_double(out, d);
  for (double d : e.box_max) put_double(out, d);
  put_string(out, e.client_id);
  put_string(out, e.reply_channel);
  return out;
}

EditMac edit_mac(std::string_view token, std::string_view channel, const octomap_rt::map_edit_t& edit) {
  ensure_sodium();
  const std::vector<uint8_t> input = edit_mac_input(channel, edit);
  crypto_auth_hmacsha256_state state;
  crypto_auth_hmacsha256_init(&state, reinterpret_cast<const unsigned char*>(token.data()), token.size());
  crypto_auth_hmacsha256_update(&state, input.data(), input.size());
  EditMac mac{};
  crypto_auth_hmacsha256_final(&state, mac.data());
  sodium_memzero(&state, sizeof state);
  return mac;
}

bool edit_mac_matches(std::string_view token, std::string_view channel, const octomap_rt::map_edit_t& edit) {
  const EditMac want = edit_mac(token, channel, edit);
  static_assert(sizeof edit.mac == std::tuple_size_v<EditMac>);
  return sodium_memcmp(want.data(), edit.mac, want.size()) == 0;
}

void sign_edit(octomap_rt::map_edit_t& edit, std::string_view token, std::string_view channel) {
  const EditMac mac = edit_mac(token, channel, edit);
  std::memcpy(edit.mac, mac.data(), mac.size());
}

int64_t random_edit_nonce() {
  ensure_sodium();
  int64_t nonce = 0;
  randombytes_buf(&nonce, sizeof nonce);
  return nonce;
}

}  // namespace ort::protocol
