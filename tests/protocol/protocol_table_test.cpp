// The Python and Java clients take the protocol's names and limits from tables generated from
// protocol/*.h (tools/protocol-table). Each generated value must equal the C++ constant, and no
// Python or Java client source may spell a channel name of its own.
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "protocol/channels.h"
#include "protocol/lcm_url.h"
#include "protocol/limits.h"
#include "protocol/version.h"

namespace ort::test {
namespace {

using namespace ort::protocol;

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// NAME -> value text (strings without their quotes, numbers without a trailing L).
std::map<std::string, std::string> table(const std::string& text, const std::regex& line) {
  std::map<std::string, std::string> out;
  for (std::sregex_iterator it(text.begin(), text.end(), line), end; it != end; ++it) out[(*it)[1]] = (*it)[2];
  return out;
}

// Every constant of the C++ home, by its generated name.
std::map<std::string, std::string> expected() {
  std::map<std::string, std::string> e = {
      {"SCAN_CHANNEL_PREFIX", kScanChannelPrefix},
      {"STATUS_CHANNEL", kStatusChannel},
      {"MAP_REQUEST_CHANNEL", kMapRequestChannel},
      {"MAP_INFO_CHANNEL", kMapInfoChannel},
      {"MAP_DELTA_CHANNEL", kMapDeltaChannel},
      {"MAP_REPLY_PREFIX", kMapReplyPrefix},
      {"QUERY_CHANNEL", kQueryChannel},
      {"QUERY_RAYS_CHANNEL", kQueryRaysChannel},
      {"QUERY_BOXES_CHANNEL", kQueryBoxesChannel},
      {"QUERY_GRID_CHANNEL", kQueryGridChannel},
      {"QUERY_DISTANCE_CHANNEL", kQueryDistanceChannel},
      {"MAP_EDIT_CHANNEL", kMapEditChannel},
      {"QUERY_REPLY_PREFIX", kQueryReplyPrefix},
      {"GRID_CHANNEL", kGridChannel},
      {"OCTOMAP_RAW_CHANNEL", kOctomapRawChannel},
      {"SHARD_NAMESPACE_PREFIX", kShardNamespacePrefix},
      {"NAMESPACE_ENV", kNamespaceEnv},
      {"DEFAULT_LCM_URL", kDefaultLcmUrl},
      {"MAX_CHANNEL_LENGTH", std::to_string(kMaxChannelLength)},
      {"DEFAULT_MAX_SCAN_POINTS", std::to_string(kDefaultMaxScanPoints)},
      {"MAX_ROBOT_ID_LENGTH", std::to_string(kMaxRobotIdLength)},
      {"MIN_SCAN_MAX_RANGE", "0.001"},
      {"MAX_MAP_FRAME_LENGTH", std::to_string(kMaxMapFrameLength)},
      {"MAX_MESSAGE_BYTES", std::to_string(kMaxMessageBytes)},
      {"MAX_INBOUND_QUERY_BYTES", std::to_string(kMaxInboundQueryBytes)},
      {"CHUNK_DATA_BYTES", std::to_string(kChunkDataBytes)},
      {"DELTA_DATA_BYTES", std::to_string(kDeltaDataBytes)},
      {"MAX_REQUESTED_CHUNKS", std::to_string(kMaxRequestedChunks)},
      {"MAX_NAME_LENGTH", std::to_string(kMaxNameLength)},
      {"MAX_TOKEN_LENGTH", std::to_string(kMaxTokenLength)},
      {"MAX_QUERY_POINTS", std::to_string(kMaxQueryPoints)},
      {"MAX_QUERY_RAYS", std::to_string(kMaxQueryRays)},
      {"MAX_QUERY_BOXES", std::to_string(kMaxQueryBoxes)},
      {"REGION_CHUNK_VOXELS", std::to_string(kRegionChunkVoxels)},
      {"GRID_CHUNK_CELLS", std::to_string(kGridChunkCells)},
      {"MAX_SHARDS", std::to_string(kMaxShards)},
      {"PROTOCOL_VERSION", std::to_string(kProtocolVersion)},
  };
  return e;
}

void expect_table(const std::map<std::string, std::string>& got) {
  for (const auto& [name, value] : expected()) {
    const auto it = got.find(name);
    ASSERT_NE(it, got.end()) << name << " is missing from the generated table";
    EXPECT_EQ(it->second, value) << name;
  }
  {
    const auto it = got.find("MIN_SCAN_MAX_RANGE");
    ASSERT_NE(it, got.end());
    EXPECT_EQ(std::stod(it->second), kMinScanMaxRange);
  }
  // A constant added to protocol/ but not to this test fails here, so the test keeps up.
  EXPECT_EQ(got.size(), expected().size());
}

TEST(ProtocolTable, PythonTableHasEveryConstantOfTheCppHome) {
  const std::string text = read_file(OCTOMAP_RT_PYTHON_TABLE);
  ASSERT_FALSE(text.empty()) << OCTOMAP_RT_PYTHON_TABLE;
  expect_table(table(text, std::regex(R"re(\n([A-Z_]+) = "?([^"\n]*)"?)re")));
}

TEST(ProtocolTable, JavaTableHasEveryConstantOfTheCppHome) {
  if (std::string(OCTOMAP_RT_JAVA_TABLE).empty()) GTEST_SKIP() << "no JDK: the Java example is not built";
  const std::string text = read_file(OCTOMAP_RT_JAVA_TABLE);
  ASSERT_FALSE(text.empty()) << OCTOMAP_RT_JAVA_TABLE;
  expect_table(table(text, std::regex(R"re(static final \w+ ([A-Z_]+) = "?(.*?)"?L?;)re")));
}

// A channel name written in a client source instead of taken from the table.
TEST(ProtocolTable, NoPythonOrJavaClientSpellsAChannelName) {
  const std::regex literal(R"re("OCTOMAP(_RT_[A-Z_]*)?")re");
  int files = 0;
  for (const char* dir :
       {"client/bindings/python/octomap_rt", "client/bindings/python/examples", "client/bindings/java/examples"}) {
    for (const auto& e :
         std::filesystem::recursive_directory_iterator(std::string(OCTOMAP_RT_SOURCE_DIR) + "/" + dir)) {
      if (!e.is_regular_file()) continue;
      const std::string path = e.path().string();
      if (path.size() < 3 || (path.substr(path.size() - 3) != ".py" && path.substr(path.size() - 5) != ".java"))
        continue;
      ++files;
      const std::string text = read_file(path);
      std::smatch m;
      EXPECT_FALSE(std::regex_search(text, m, literal)) << path << " spells " << m.str();
    }
  }
  EXPECT_GT(files, 3);
}

}  // namespace
}  // namespace ort::test
