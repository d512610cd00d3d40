// Map pictures: boxes of known place and size appear where they are, at the right scale,
// in the right colour; --z cuts; the PNG holds the picture; the command writes one.
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "render/height_colours.h"
#include "render/map_render.h"
#include "render/png_file.h"

namespace ort::render {
namespace {

constexpr double kRes = 0.1;
constexpr Rgb kWhite{255, 255, 255};

// Marks every voxel whose centre lies in [lo, hi) occupied (corners on the 0.1 m grid).
void add_box(octomap::OcTree& tree, std::array<double, 3> lo, std::array<double, 3> hi) {
  for (double x = lo[0] + kRes / 2; x < hi[0]; x += kRes)
    for (double y = lo[1] + kRes / 2; y < hi[1]; y += kRes)
      for (double z = lo[2] + kRes / 2; z < hi[2]; z += kRes) tree.updateNode(octomap::point3d(x, y, z), true);
}

// Equal up to rounding of the float box corners (one step of a channel).
void expect_colour(Rgb got, Rgb want) {
  EXPECT_NEAR(got.r, want.r, 1);
  EXPECT_NEAR(got.g, want.g, 1);
  EXPECT_NEAR(got.b, want.b, 1);
}

struct PixelRect {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;  // inclusive
  int width() const { return x1 - x0 + 1; }
  int height() const { return y1 - y0 + 1; }
};

// The bounding rectangle of the pixels of the map area that differ from the background,
// within [x0, x1) x [y0, y1).
PixelRect drawn_pixels(const MapPicture& p, int x0, int y0, int x1, int y1) {
  PixelRect r;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      if (!(p.canvas.at(x, y) == kWhite)) {
        r.x0 = std::min(r.x0, x), r.x1 = std::max(r.x1, x);
        r.y0 = std::min(r.y0, y), r.y1 = std::max(r.y1, y);
      }
  return r;
}

// A 1 m x 0.5 m x 0.5 m box east and north of a 0.2 m marker cube at the origin corner.
octomap::OcTree two_boxes() {
  octomap::OcTree tree(kRes);
  add_box(tree, {0, 0, 0}, {0.2, 0.2, 0.2});
  add_box(tree, {3, 2, 0}, {4, 2.5, 0.5});
  return tree;
}

TEST(Render, TopViewShowsTheBoxWhereItIsAtScale) {
  const octomap::OcTree tree = two_boxes();
  RenderOptions opt;
  opt.width = 800;
  opt.free = FreeSpace::hidden;
  const MapPicture p = render_map(tree, opt);
  const int map_h = p.camera.height(), mid_x = p.canvas.width() / 2;
  ASSERT_GT(map_h, 100);
  // The map spans x 0..4 m over 800 - 2 x 16 px: 192 px/m.
  EXPECT_NEAR(p.camera.pixels_per_metre(), (800 - 32) / 4.0, 1e-4);
  // The big box is in the right (east) half, at the top (north); the marker bottom left.
  const PixelRect box = drawn_pixels(p, mid_x, 0, p.canvas.width(), map_h);
  const PixelRect marker = drawn_pixels(p, 0, 0, mid_x, map_h);
  ASSERT_GE(box.x1, 0);
  ASSERT_GE(marker.x1, 0);
  const double ppm = p.camera.pixels_per_metre();
  EXPECT_NEAR(box.width(), 1.0 * ppm, 1.5);
  EXPECT_NEAR(box.height(), 0.5 * ppm, 1.5);
  EXPECT_NEAR(marker.width(), 0.2 * ppm, 1.5);
  EXPECT_NEAR(box.x0 - marker.x0, 3.0 * ppm, 1.5);  // west edges 3 m apart
  EXPECT_NEAR(marker.y1 - box.y1, 2.0 * ppm, 1.5);  // south edges 2 m apart, north is up
  // Where the camera says it is, and filled inside.
  const ScreenPoint nw = p.camera.project(3, 2.5, 0.5), se = p.camera.project(4, 2, 0.5);
  EXPECT_NEAR(box.x0, nw.x, 1.0);
  EXPECT_NEAR(box.y0, nw.y, 1.0);
  EXPECT_NEAR(box.x1 + 1, se.x, 1.0);
  EXPECT_NEAR(box.y1 + 1, se.y, 1.0);
  for (int y = box.y0 + 2; y < box.y1 - 1; ++y)
    for (int x = box.x0 + 2; x < box.x1 - 1; ++x) ASSERT_FALSE(p.canvas.at(x, y) == kWhite) << x << "," << y;
}

TEST(Render, ColourIsTheHeightOfTheVoxel) {
  octomap::OcTree tree(kRes);
  add_box(tree, {0, 0, 0}, {1, 1, 0.1});  // floor slab at z 0..0.1
  add_box(tree, {2, 0, 1.9}, {3, 1, 2});  // shelf at z 1.9..2
  RenderOptions opt;
  opt.width = 600;
  opt.free = FreeSpace::hidden;
  const MapPicture p = render_map(tree, opt);
  const HeightColours colours(0, 2);  // the ramp spans the occupied heights
  const ScreenPoint low = p.camera.project(0.55, 0.55, 0.1), high = p.camera.project(2.55, 0.55, 2);
  expect_colour(p.canvas.at(int(low.x), int(low.y)), colours.at(0.05));
  expect_colour(p.canvas.at(int(high.x), int(high.y)), colours.at(1.95));
  EXPECT_FALSE(colours.at(0.05) == colours.at(1.95));
}

TEST(Render, ObliqueViewShowsTopFacesAboveTheirBase) {
  octomap::OcTree tree(kRes);
  add_box(tree, {0, 0, 0}, {0.1, 0.1, 3});  // a 3 m pillar, one voxel wide (so never pruned)
  add_box(tree, {2, 2, 0}, {2.5, 2.5, 0.1});
  RenderOptions opt;
  opt.view = View::oblique;
  opt.width = 600;
  opt.free = FreeSpace::hidden;
  const MapPicture p = render_map(tree, opt);
  const ScreenPoint top = p.camera.project(0.05, 0.05, 3), base = p.camera.project(0.05, 0.05, 0);
  EXPECT_LT(top.y, base.y - 100);  // up is up, and 3 m is long
  const HeightColours colours(0, 3);
  expect_colour(p.canvas.at(int(top.x), int(top.y)), colours.at(2.95));  // the lit top face, top voxel's height
  EXPECT_FALSE(p.canvas.at(int(base.x), int(base.y - 20)) == kWhite);    // a side face
}

TEST(Render, HeightRangeCutsWhatIsOutside) {
  octomap::OcTree tree(kRes);
  add_box(tree, {0, 0, 0}, {1, 1, 0.5});
  add_box(tree, {0, 2, 2}, {1, 3, 2.5});  // a ceiling over another spot
  RenderOptions opt;
  opt.width = 400;
  opt.free = FreeSpace::hidden;
  opt.heights.max = 1.0;
  const MapPicture p = render_map(tree, opt);
  EXPECT_NEAR(p.extent.hi[1], 1.0, 1e-6);  // the ceiling is gone from the extent
  const ScreenPoint floor = p.camera.project(0.5, 0.5, 0.5);
  EXPECT_FALSE(p.canvas.at(int(floor.x), int(floor.y)) == kWhite);
  opt.heights = {3.0, 4.0};
  EXPECT_THROW(render_map(tree, opt), std::invalid_argument);  // nothing there: said, not a blank picture
}

TEST(Render, FreeSpaceIsAFaintFootprintUnderTheVoxels) {
  octomap::OcTree tree(kRes);
  tree.insertRay(octomap::point3d(0.05f, 0.05f, 0.05f), octomap::point3d(3.05f, 0.05f, 0.05f));
  RenderOptions opt;
  opt.width = 400;
  const MapPicture p = render_map(tree, opt);
  const ScreenPoint free_spot = p.camera.project(1.5, 0.05, 0.1), end = p.camera.project(3.05, 0.05, 0.1);
  const Rgb f = p.canvas.at(int(free_spot.x), int(free_spot.y));
  EXPECT_FALSE(f == kWhite);
  EXPECT_GT(int(f.r) + f.g + f.b, 3 * 200);                // faint
  EXPECT_FALSE(p.canvas.at(int(end.x), int(end.y)) == f);  // the occupied end is drawn over it
}

TEST(Render, PngHoldsThePicture) {
  const MapPicture p = render_map(two_boxes(), RenderOptions{});
  const std::string path = testing::TempDir() + "/render_test.png";
  write_png(p.canvas, path);
  const Canvas back = read_png(path);
  ASSERT_EQ(back.width(), p.canvas.width());
  ASSERT_EQ(back.height(), p.canvas.height());
  EXPECT_TRUE(back.pixels() == p.canvas.pixels());
  EXPECT_THROW(read_png(path + ".missing"), PngError);
}

TEST(Render, CommandDrawsAMapFile) {
  const std::string dir = testing::TempDir() + "/render_cmd";
  std::filesystem::create_directories(dir);
  const octomap::OcTree tree = two_boxes();
  ASSERT_TRUE(tree.writeBinaryConst(dir + "/map.bt"));
  const std::string cli = OCTOMAP_RT_CLI;
  ASSERT_EQ(std::system((cli + " render " + dir + "/map.bt -o " + dir + "/top.png --width 500 2>/dev/null").c_str()),
            0);
  ASSERT_EQ(std::system(
                (cli + " render " + dir + "/map.bt -o " + dir + "/obl.png --view oblique --z 0:1 2>/dev/null").c_str()),
            0);
  EXPECT_EQ(read_png(dir + "/top.png").width(), 500);
  EXPECT_EQ(read_png(dir + "/obl.png").width(), 1200);
  EXPECT_NE(std::system((cli + " render " + dir + "/map.bt -o " + dir + "/x.png --z 2:1 2>/dev/null").c_str()), 0);
  EXPECT_NE(std::system((cli + " render " + dir + "/none.bt -o " + dir + "/x.png 2>/dev/null").c_str()), 0);
}

}  // namespace
}  // namespace ort::render
