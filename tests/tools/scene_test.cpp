// The scene generator: its grid walk finds the same surfaces as a brute-force search, scans
// are deterministic, points lie on the surfaces they were cast at (which checks the sensor
// rotation against OctoMap's pose6d), poses stay out of walls, and the presets have the
// scale of the paper's Table I.
#include <cmath>
#include <filesystem>
#include <limits>

#include <gtest/gtest.h>

#include "scene/procedural_worlds.h"
#include "scene/range_sensors.h"
#include "scene/real_map_world.h"
#include "scene/scan_set.h"
#include "scene/scene_geometry.h"
#include "scene/scene_presets.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

using scene::Box;
using scene::Vec3;

double brute_force_hit(const std::vector<Box>& boxes, const Vec3& o, const Vec3& d, double max_t) {
  double best = std::numeric_limits<double>::infinity();
  for (const Box& b : boxes) {
    double t0 = 0, t1 = max_t;
    bool hit = true;
    for (int i = 0; i < 3 && hit; ++i) {
      if (d[i] == 0) {
        hit = o[i] >= b.lo[i] && o[i] <= b.hi[i];
        continue;
      }
      double ta = (b.lo[i] - o[i]) / d[i], tb = (b.hi[i] - o[i]) / d[i];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      hit = t0 <= t1;
    }
    if (hit) best = std::min(best, t0);
  }
  return best;
}

TEST(SceneGeometry, GridWalkFindsTheNearestBoxLikeBruteForce) {
  const scene::World w = scene::make_indoor_building(3, scene::IndoorParams{});
  uint64_t s = 12345;
  auto uni = [&] {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return double(s >> 11) / 9007199254740992.0;
  };
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 o{uni() * 46, uni() * 36, 0.2 + uni() * 4};
    Vec3 d{uni() - 0.5, uni() - 0.5, uni() - 0.5};
    if (i % 10 == 0) d = {1, 0, 0};  // axis-aligned rays too
    const double n = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    d = d * (1.0 / n);
    const double expect = brute_force_hit(w.scene.boxes.boxes, o, d, 30.0);
    const double got = scene::cast_ray(w.scene.boxes, o, d, 30.0);
    if (expect <= 30.0) {
      ++hits;
      ASSERT_NEAR(got, expect, 1e-9) << "ray " << i;
    } else {
      ASSERT_GT(got, 30.0) << "ray " << i;
    }
  }
  EXPECT_GT(hits, 15000);
}

TEST(ScenePresets, DeterministicFromTheSeed) {
  PresetOptions o;
  o.scan_scale = o.point_scale = 0.05;
  const ScanSet a = make_preset("skt-corridor", o), b = make_preset("skt-corridor", o);
  o.seed = 2;
  const ScanSet c = make_preset("skt-corridor", o);
  ASSERT_EQ(a.scans.size(), b.scans.size());
  ASSERT_GT(a.total_points(), 0u);
  bool differs = a.total_points() != c.total_points();
  for (size_t i = 0; i < a.scans.size(); ++i) {
    ASSERT_EQ(a.scans[i].points.size(), b.scans[i].points.size());
    for (size_t k = 0; k < a.scans[i].points.size(); ++k) ASSERT_EQ(a.scans[i].points[k], b.scans[i].points[k]);
    if (!differs && i < c.scans.size() && c.scans[i].points.size() == a.scans[i].points.size())
      differs = c.scans[i].points[0] != a.scans[i].points[0];
  }
  EXPECT_TRUE(differs) << "another seed should give another scene";
}

// World-frame points (OctoMap's Pointcloud::transform with the scan's pose6d) must lie where
// the sensor's beam met a surface: cast from the origin towards each point and compare.
void expect_points_on_surfaces(const std::string& preset, const scene::World& w, double tolerance) {
  PresetOptions o;
  o.scan_scale = 0.05;
  o.point_scale = 0.02;
  const ScanSet set = make_preset(preset, o);
  ASSERT_FALSE(set.scans.empty());
  size_t checked = 0, off = 0;
  for (const PosedScan& s : set.scans) {
    const octomap::point3d org = sensor_origin(s);
    const Vec3 o{org.x(), org.y(), org.z()};
    EXPECT_FALSE(scene::inside_solid(w.scene, o, 0.05)) << preset << ": sensor inside a solid at " << org;
    const octomap::Pointcloud world = world_points(s);
    for (size_t i = 0; i < world.size(); ++i) {
      const Vec3 p{world[i].x(), world[i].y(), world[i].z()};
      const Vec3 d = p - o;
      const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
      const double t = scene::cast_ray(w.scene, o, d * (1.0 / len), 200.0);
      ++checked;
      if (std::abs(t - len) > tolerance) ++off;
    }
  }
  EXPECT_GT(checked, 100u);
  // Noise moves points along the beam only; a few beams graze an edge and may meet another
  // surface when re-cast from a float origin.
  EXPECT_LT(double(off), 0.01 * checked) << preset << ": " << off << " of " << checked << " points off their surface";
}

TEST(ScenePresets, PointsLieOnTheSurfacesTheirBeamsHit) {
  expect_points_on_surfaces("fr079", scene::make_indoor_building(1, scene::IndoorParams{}), 0.06);
  expect_points_on_surfaces("campus", scene::make_outdoor_campus(1, scene::CampusParams{}), 0.2);
}

TEST(ScenePresets, TableOneScale) {
  for (const PresetInfo& p : preset_catalog()) {
    if (p.name == "fr079-real") continue;
    PresetOptions o;
    o.scan_scale = 3.0 / p.scans;  // three scans spread over the tour, full sensor resolution
    const ScanSet set = make_preset(p.name, o);
    ASSERT_EQ(set.scans.size(), 3u) << p.name;
    const double per_scan = double(set.total_points()) / set.scans.size();
    EXPECT_NEAR(per_scan, p.points_per_scan, 0.25 * p.points_per_scan) << p.name;
    PresetOptions full;
    full.scan_scale = 1.0;
    full.point_scale = 1e-4;  // a full trajectory of tiny scans: the scan count of Table I
    EXPECT_EQ(int(make_preset(p.name, full).scans.size()), p.scans) << p.name;
  }
}

TEST(ScenePresets, RealFr079MapPreset) {
  const std::string dir = data_dir();
  if (!std::filesystem::exists(dir + "/octomap_share/geb079.bt")) GTEST_SKIP() << "geb079.bt not in " << dir;
  PresetOptions o;
  o.scan_scale = 0.05;
  o.point_scale = 0.05;
  o.data_dir = dir;
  const ScanSet set = make_preset("fr079-real", o);
  EXPECT_EQ(set.scans.size(), 3u);
  EXPECT_GT(set.total_points(), 3u * 1000);
  const scene::World w = scene::make_world_from_octomap(dir + "/octomap_share/geb079.bt", 1.0);
  EXPECT_GT(scene::path_length(w.path), 20.0) << "the corridor of FR-079 is ~40 m long";
}

TEST(ScanGraphFiles, RoundTrip) {
  PresetOptions o;
  o.scan_scale = o.point_scale = 0.05;
  const ScanSet set = make_preset("fr079", o);
  const std::string path = testing::TempDir() + "/fr079_ci.graph";
  save_scan_graph(set, path);
  const ScanSet back = load_scan_graph(path);
  ASSERT_EQ(back.scans.size(), set.scans.size());
  for (size_t i = 0; i < set.scans.size(); ++i) {
    ASSERT_EQ(back.scans[i].points.size(), set.scans[i].points.size());
    EXPECT_EQ(world_points(back.scans[i])[0], world_points(set.scans[i])[0]);
  }
}

TEST(ScalePresets, ParsesNamesAndNumbers) {
  EXPECT_DOUBLE_EQ(parse_scale("tiny"), 0.02);
  EXPECT_DOUBLE_EQ(parse_scale("ci"), 0.05);
  EXPECT_DOUBLE_EQ(parse_scale("0.5"), 0.5);
  EXPECT_THROW(parse_scale("2"), std::invalid_argument);
  EXPECT_THROW(parse_scale("big"), std::invalid_argument);
  EXPECT_THROW(make_preset("no-such-preset", PresetOptions{}), std::runtime_error);
}

}  // namespace
}  // namespace ort::test
