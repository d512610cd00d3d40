// The map protocol's pieces on their own: the fixed offsets the pre-decode checks rely on,
// crafted messages refused with a reason, the delta codec (round trip, part size limit,
// corrupt payloads refused) and the client's snapshot assembly.
#include <climits>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "map_client/snapshot_assembly.h"
#include "protocol/delta_codec.h"
#include "protocol/inbound_checks.h"
#include "protocol/limits.h"
#include "protocol/map_protocol.h"
#include "protocol/wire_layout.h"
#include "protocol/zstd_codec.h"

namespace ort::test {
namespace {

using namespace ort::protocol;

template <class T>
std::vector<uint8_t> encode(const T& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

int32_t be32(const std::vector<uint8_t>& b, size_t off) {
  return static_cast<int32_t>((uint32_t(b[off]) << 24) | (uint32_t(b[off + 1]) << 16) | (uint32_t(b[off + 2]) << 8) |
                              uint32_t(b[off + 3]));
}
void put_be32(std::vector<uint8_t>& b, size_t off, int32_t v) {
  for (int i = 0; i < 4; ++i) b[off + i] = static_cast<uint8_t>(static_cast<uint32_t>(v) >> (24 - 8 * i));
}

// The refusal's short name ("" when the message was taken).
std::string fault_name(const WireCheck& c) { return wire_fault_name(c.fault); }

octomap_rt::map_request_t request(int n) {
  octomap_rt::map_request_t r{};
  r.format = 2;
  r.chunk_indices.assign(n, 1);
  r.num_chunk_indices = n;
  r.client_id = "c1";
  r.reply_channel = "OCTOMAP_RT_MAP_REPLY_C1";
  return r;
}

TEST(Protocol, CountsSitAtTheirFixedOffsets) {
  octomap_rt::map_chunk_t c{};
  c.data.assign(7, 1);
  c.data_size = 7;
  EXPECT_EQ(be32(encode(c), kChunkDataSizeOffset), 7);
  octomap_rt::map_delta_t d{};
  d.data.assign(9, 1);
  d.data_size = 9;
  EXPECT_EQ(be32(encode(d), kDeltaDataSizeOffset), 9);
  EXPECT_EQ(be32(encode(request(5)), kRequestNumIndicesOffset), 5);
  octomap_rt::map_info_t m{};
  m.num_producers = 2;
  m.producer_last_seq = {1, 2};
  m.producer_id = {"a", "b"};
  EXPECT_EQ(be32(encode(m), kInfoNumProducersOffset), 2);
}

// The walk's typed faults, which the daemon maps to its reject reasons and the query answers
// describe to clients: each in encoding order, the broken bound carried with its fault.
TEST(Protocol, TheWireWalkNamesEachFaultWithItsBound) {
  const auto good = encode(request(3));
  const int64_t hash = octomap_rt::map_request_t::getHash();
  const auto layout = {wire_fixed(kRequestNumIndicesOffset - 8), wire_count(5), wire_array(4), wire_string(64),
                       wire_string(64)};
  const auto check = [&](const std::vector<uint8_t>& b, size_t n) { return check_wire(b.data(), n, hash, layout); };
  EXPECT_TRUE(check(good, good.size()).ok());
  EXPECT_EQ(check(good, 7).fault, WireFault::kTruncated);
  auto b = good;
  put_be32(b, kRequestNumIndicesOffset, 6);
  const WireCheck too_many = check(b, b.size());
  EXPECT_EQ(too_many.fault, WireFault::kCountTooLarge);
  EXPECT_EQ(too_many.limit, 5);
  EXPECT_EQ(describe(too_many), "count too large (at most 5)");
  b = good;
  b.back() = 'x';  // the last string's NUL
  EXPECT_EQ(check(b, b.size()).fault, WireFault::kStringNotTerminated);
  EXPECT_STREQ(wire_fault_name(WireFault::kStringNotTerminated), "string not terminated");
  b = good;
  b.push_back(0);
  EXPECT_EQ(describe(check(b, b.size())), "trailing bytes");
  EXPECT_EQ(describe(WireCheck{}), "");
}

TEST(Protocol, CraftedRequestsAreRefusedWithAReason) {
  octomap_rt::map_request_t out{};
  const auto good = encode(request(3));
  EXPECT_EQ(fault_name(check_request(good.data(), good.size(), out)), "");
  EXPECT_EQ(out.chunk_indices.size(), 3u);
  auto b = good;
  b[0] ^= 1;
  EXPECT_EQ(fault_name(check_request(b.data(), b.size(), out)), "wrong fingerprint");
  b = good;
  put_be32(b, kRequestNumIndicesOffset, -1);
  EXPECT_EQ(fault_name(check_request(b.data(), b.size(), out)), "negative count");
  put_be32(b, kRequestNumIndicesOffset, 0x7fffffff);
  EXPECT_EQ(fault_name(check_request(b.data(), b.size(), out)), "count too large");
  put_be32(b, kRequestNumIndicesOffset, 1000);
  EXPECT_EQ(fault_name(check_request(b.data(), b.size(), out)), "count exceeds data");
  EXPECT_EQ(fault_name(check_request(good.data(), 20, out)), "truncated");
  b = good;
  b.push_back(0);
  EXPECT_EQ(fault_name(check_request(b.data(), b.size(), out)), "trailing bytes");
  b = good;
  b[b.size() - 28] = 0xff;  // the reply channel's string length
  EXPECT_NE(fault_name(check_request(b.data(), b.size(), out)), "");
  // Found by fuzz_map_request: a string length of INT32_MIN made LCM's generated decode()
  // compute len - 1 (signed overflow) and copy from past the buffer. Lengths are walked first.
  const size_t client_len = kRequestNumIndicesOffset + 4 + 4 * 3;
  b = good;
  put_be32(b, client_len, INT32_MIN);
  EXPECT_EQ(fault_name(check_request(b.data(), b.size(), out)), "bad string length");
  put_be32(b, client_len, 0);
  EXPECT_EQ(fault_name(check_request(b.data(), b.size(), out)), "bad string length");
  b = good;
  b[client_len + 4 + size_t(be32(good, client_len)) - 1] = 'x';
  EXPECT_EQ(fault_name(check_request(b.data(), b.size(), out)), "string not terminated");
}

// map_info_t carries one string per producer after the array of their seqs: each is walked.
TEST(Protocol, CraftedInfosAreRefusedWithAReason) {
  octomap_rt::map_info_t m{};
  m.num_producers = 2;
  m.producer_last_seq = {1, 2};
  m.producer_id = {"robot_a", "robot_b"};
  m.server_id = "s";
  m.map_frame = "map";
  const auto good = encode(m);
  octomap_rt::map_info_t out{};
  EXPECT_EQ(fault_name(check_info(good.data(), good.size(), out)), "");
  EXPECT_EQ(out.producer_id.size(), 2u);
  EXPECT_EQ(out.producer_id[1], "robot_b");
  const size_t first_id = kInfoNumProducersOffset + 4 + 8 * 2;  // after the seqs
  const size_t second_id = first_id + 4 + size_t(be32(good, first_id));
  auto b = good;
  put_be32(b, second_id, INT32_MIN);
  EXPECT_EQ(fault_name(check_info(b.data(), b.size(), out)), "bad string length");
  put_be32(b, second_id, 1000);  // within the bound, beyond the bytes
  EXPECT_EQ(fault_name(check_info(b.data(), b.size(), out)), "truncated");
  b = good;
  b[second_id + 4 + size_t(be32(good, second_id)) - 1] = 'x';
  EXPECT_EQ(fault_name(check_info(b.data(), b.size(), out)), "string not terminated");
  b = good;
  put_be32(b, kInfoNumProducersOffset, 3);  // a third id the bytes do not hold
  EXPECT_NE(fault_name(check_info(b.data(), b.size(), out)), "");
  put_be32(b, kInfoNumProducersOffset, 5000);
  EXPECT_EQ(fault_name(check_info(b.data(), b.size(), out)), "count too large");
}

std::vector<VoxelChange> random_changes(size_t n, int8_t mode, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> k(32000, 33500), c(1, 2);
  std::map<uint64_t, float> m;
  while (m.size() < n) {
    const auto key = pack_key(octomap::OcTreeKey(k(rng), k(rng), k(rng)));
    m[key] = mode == octomap_rt::map_delta_t::MODE_CLASS ? float(c(rng)) : float(k(rng) - 32750) / 300.0f;
  }
  std::vector<VoxelChange> v;
  for (auto& [key, val] : m) v.push_back({key, val});
  return v;
}

TEST(Protocol, DeltaPartsRoundTripAndFitOneDatagram) {
  for (int8_t mode : {octomap_rt::map_delta_t::MODE_CLASS, octomap_rt::map_delta_t::MODE_LOG_ODDS}) {
    const auto changes = random_changes(200000, mode, 7);
    const auto parts = encode_delta_parts(changes, mode, 3, kDeltaDataBytes);
    EXPECT_GT(parts.size(), 1u);
    std::vector<VoxelChange> back;
    for (const DeltaPart& p : parts) {
      EXPECT_LE(p.data.size(), kDeltaDataBytes);
      const auto v = decode_delta_part(p.data, p.num_voxels, p.uncompressed_size, mode);  // each part on its own
      back.insert(back.end(), v.begin(), v.end());
    }
    EXPECT_EQ(back, changes);
  }
}

TEST(Protocol, CorruptDeltaPayloadsAreRefused) {
  const int8_t mode = octomap_rt::map_delta_t::MODE_CLASS;
  const auto changes = random_changes(1000, mode, 3);
  const DeltaPart p = encode_delta_parts(changes, mode, 3, kDeltaDataBytes).at(0);
  EXPECT_THROW(decode_delta_part(p.data, p.num_voxels + 1, p.uncompressed_size, mode), CodecError);
  EXPECT_THROW(decode_delta_part(p.data, p.num_voxels, p.uncompressed_size - 1, mode), CodecError);
  EXPECT_THROW(decode_delta_part(p.data, -1, p.uncompressed_size, mode), CodecError);
  EXPECT_THROW(decode_delta_part(p.data, p.num_voxels, p.uncompressed_size, 7), CodecError);
  std::string bad = p.data;
  bad[bad.size() / 2] ^= 0x55;
  EXPECT_ANY_THROW(decode_delta_part(bad, p.num_voxels, p.uncompressed_size, mode));
  // Values that are not a class.
  std::string raw;
  raw += '\x01';
  raw += '\x07';
  const std::string z = zstd_compress(raw, 1);
  EXPECT_THROW(decode_delta_part(z, 1, 2, mode), CodecError);
}

TEST(Protocol, SnapshotAssemblyNamesMissingChunksAndChecksTheHash) {
  std::string blob(150000, 'x');
  for (size_t i = 0; i < blob.size(); ++i) blob[i] = static_cast<char>(i * 7);
  const int32_t n = static_cast<int32_t>((blob.size() + kChunkDataBytes - 1) / kChunkDataBytes);
  auto chunk = [&](int32_t i) {
    octomap_rt::map_chunk_t c{};
    c.snapshot_id = 5;
    c.num_chunks = n;
    c.chunk_index = i;
    c.chunk_size = kChunkDataBytes;
    c.offset = int64_t(i) * kChunkDataBytes;
    c.total_size = blob.size();
    c.blob_hash = blob_hash(blob.data(), blob.size());
    c.format = 2;
    c.uncompressed_size = blob.size();
    const size_t len = std::min<size_t>(kChunkDataBytes, blob.size() - c.offset);
    c.data.assign(blob.begin() + c.offset, blob.begin() + c.offset + len);
    c.data_size = len;
    return c;
  };
  client::SnapshotAssembly a;
  EXPECT_EQ(a.add(chunk(0)), "");
  EXPECT_EQ(a.add(chunk(2)), "");
  EXPECT_EQ(a.missing(), std::vector<int32_t>{1});
  auto other = chunk(1);
  other.snapshot_id = 6;
  EXPECT_EQ(a.add(other), "chunk of another snapshot");
  auto shifted = chunk(1);
  shifted.offset += 1;
  EXPECT_EQ(a.add(shifted), "chunk offset or size wrong");
  EXPECT_EQ(a.add(chunk(1)), "");
  ASSERT_TRUE(a.complete());
  EXPECT_EQ(a.blob(), blob);
}

}  // namespace
}  // namespace ort::test
