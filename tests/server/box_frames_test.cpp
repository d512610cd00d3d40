// A distance box's blob made by z-slabs (daemon/queries/box_frames.h): on a real map's box,
// the frames decompress to the bytes of the box's field cut and clamped whole (answer_box),
// before and after the grid changes (the field brought up to date by the field cache, the
// blob by the frames kept from the last reply); a change near the box's top keeps the lower
// slabs' frames and only those; a field unchanged keeps every frame; slabs of 0 cells are one
// frame; no compression is the raw bytes. And protocol::zstd_decompress across frames: their sum, refused when cut or too large.
#include <gtest/gtest.h>

#include <cstring>

#include "daemon/queries/box_frames.h"
#include "distance/squared_edt.h"
#include "protocol/zstd_codec.h"
#include "query/query_test_maps.h"

namespace ort::test {
namespace {

const octomap::OcTree& scan_dat() {
  for (const NamedMap& m : query_test_maps())
    if (m.tree->getResolution() == 0.1) return *m.tree;
  throw std::runtime_error("no 0.1 m map among the query test maps");
}

// The bytes a single frame of the whole box would hold: squared distances, then gradients.
std::string whole_bytes(const distance::BoxRead& r, const distance::DistanceField& f, bool gradient) {
  const distance::BoxDistances b = distance::answer_box(r, f, gradient);
  std::string raw(b.squared.size() * 4 + b.gradient.size() * 4, '\0');
  std::memcpy(raw.data(), b.squared.data(), b.squared.size() * 4);
  if (gradient) std::memcpy(raw.data() + b.squared.size() * 4, b.gradient.data(), b.gradient.size() * 4);
  return raw;
}

struct SlabBox {
  const octomap::OcTree& tree = scan_dat();
  distance::DistanceOptions opt;
  distance::SquaredEdt edt = distance::cpu_edt(2);
  distance::BoxRead read;
  distance::FieldCache cache;
  SlabBox() {
    opt.max_distance = 0.5;  // 6 cells of padding: a change reaches 7 layers of the 30
    // 8 x 8 x 3 m (80 x 80 x 30 cells: slabs of 10 layers) around the map's first sensor origin.
    const double lo[3] = {-2.0, -4.0, -1.0}, hi[3] = {5.99, 3.99, 1.99};
    read = distance::read_box(tree, lo, hi, opt, {});
  }
  daemon::BoxBlob blob(const distance::DistanceField& f, bool gradient, int level = 1) {
    return daemon::box_blob(read, f, gradient, level, 3, "box", &cache.kept_frames());
  }
};

TEST(BoxFrames, SlabsDecompressToTheWholeBoxAndKeepTheUnchangedOnes) {
  SlabBox b;
  ASSERT_EQ(b.read.cells.dims.nz, 30);
  ASSERT_EQ(int64_t(b.read.cells.dims.nx) * b.read.cells.dims.ny, 6400);
  distance::OccupancyGrid grid = b.read.grid;
  const distance::DistanceField& f0 = b.cache.update(grid, b.edt, b.read.resolution, b.opt, 1);
  const daemon::BoxBlob first = b.blob(f0, true);
  EXPECT_EQ(first.frames, 6) << "3 slabs of 10 layers, distances and gradients";
  EXPECT_EQ(first.frames_kept, 0);
  const std::string want0 = whole_bytes(b.read, f0, true);
  EXPECT_EQ(first.raw_size, int64_t(want0.size()));
  EXPECT_EQ(protocol::zstd_decompress(first.bytes, want0.size()), want0);

  const daemon::BoxBlob same = b.blob(f0, true);
  EXPECT_EQ(same.frames_kept, same.frames);
  EXPECT_EQ(same.bytes, first.bytes);

  // Obstacles in the box's layer 27 (grid layer 27 + pad): the field changes in layers 20 and up
  // (gradients one layer further), so the frames of layers 0-9 and 10-19 stay as they were.
  const distance::GridDims d = grid.box.dims;
  const int64_t k = 27 + b.read.pad;
  for (int64_t i = 20; i < 60; i += 7) grid.occupied[size_t((k * d.ny + 40) * d.nx + i)] ^= 1;
  const distance::DistanceField& f1 = b.cache.update(grid, b.edt, b.read.resolution, b.opt, 2);
  EXPECT_EQ(b.cache.stats().partial, 1) << "the change is meant to be transformed in part";
  const std::string want1 = whole_bytes(b.read, distance::compute_field(grid, b.edt, b.read.resolution, b.opt), true);
  ASSERT_NE(want1, want0) << "the change must show in the box";
  const daemon::BoxBlob after = b.blob(f1, true);
  EXPECT_EQ(protocol::zstd_decompress(after.bytes, want1.size()), want1);
  EXPECT_EQ(after.frames_kept, 4) << "the two lower slabs' distances and gradients, nothing else";

  // Slabs of 0 cells: the box one frame (the reply as before the slabs), the same bytes decompressed.
  const daemon::BoxBlob one = daemon::box_blob(b.read, f1, true, 1, 3, "box", nullptr, 0);
  EXPECT_EQ(one.frames, 2) << "distances and gradients, a frame each";
  EXPECT_EQ(protocol::zstd_decompress(one.bytes, want1.size()), want1);

  const daemon::BoxBlob plain = b.blob(f1, false, 0);
  EXPECT_EQ(plain.frames, 0);
  EXPECT_EQ(plain.bytes, whole_bytes(b.read, f1, false));
}

TEST(BoxFrames, DecompressAcrossFramesChecksTheirSum) {
  const std::string a(70000, 'a'), z(5000, 'z');
  const std::string two = protocol::zstd_compress(a, 1) + protocol::zstd_compress(z, 3);
  EXPECT_EQ(protocol::zstd_decompress(two, a.size() + z.size()), a + z);
  EXPECT_THROW(protocol::zstd_decompress(two, a.size() + z.size() - 1), protocol::CodecError);
  EXPECT_THROW(protocol::zstd_decompress(two.substr(0, two.size() - 3), 1 << 20), protocol::CodecError);
  EXPECT_THROW(protocol::zstd_decompress(two + "junk", 1 << 20), protocol::CodecError);
  EXPECT_THROW(protocol::zstd_decompress("", 1 << 20), protocol::CodecError);
}

}  // namespace
}  // namespace ort::test
