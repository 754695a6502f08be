// "render" jobs on the farm: the image's tiles as bricks on real frep-worker processes. The
// merged hits are castRegion's over the whole image, bit for bit, for any worker count and tile
// size; the tile codec rejects malformed input without reading out of bounds.
#include <cmath>
#include <cstring>

#include "farm_test_util.h"

using namespace farmtest;

namespace {

JobSpec renderJob(int width, int height) {
  JobSpec j = partJob("render", 8);
  GridSpec g;
  g.origin = {0, 0, 0}, g.dims = {width, height, 1}, g.voxel = 1;
  setGrid(j, g);
  const Camera cam = orbitCamera({0, 0, 0}, -50, 30, 5, true, 0.3);
  RenderSpec& r = *j.mutable_render();
  for (int i = 0; i < 3; ++i) {
    r.add_eye(cam.eye[size_t(i)]), r.add_right(cam.right[size_t(i)]);
    r.add_up(cam.up[size_t(i)]), r.add_forward(cam.forward[size_t(i)]);
    r.add_clip_lo(-1.5), r.add_clip_hi(1.5);
  }
  r.set_perspective(true);
  r.set_half_width(cam.halfWidth);
  r.set_near_depth(2.0), r.set_far_depth(8.0);
  return j;
}

void expectSameHits(const std::vector<RayHit>& a, const std::vector<RayHit>& b) {
  ASSERT_EQ(a.size(), b.size());
  size_t hits = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].kind, b[i].kind) << i;
    ASSERT_EQ(a[i].depth, b[i].depth) << i;
    ASSERT_EQ(a[i].point, b[i].point) << i;
    ASSERT_EQ(a[i].normal, b[i].normal) << i;
    hits += a[i].kind != RayHit::kNone;
  }
  EXPECT_GT(hits, a.size() / 10);
}

}  // namespace

TEST(RenderFarm, ZeroOneAndTwoWorkersGiveTheWholeImagesHits) {
  const JobSpec j = renderJob(100, 70);
  const RenderOptions opt = renderOptionsOf(j);
  const std::vector<RayHit> ref = castRegion(compileJobModel(j), cameraOf(j), opt, PixelRegion{0, 0, 100, 70});
  for (int w : {0, 1, 2}) {
    SCOPED_TRACE(w);
    FarmOutcome o = runJob(j, fast(w, 32));
    EXPECT_EQ(o.report.operation, "render");
    EXPECT_EQ(o.report.bricks, 12u);  // 4 x 3 tiles of 32 pixels
    EXPECT_TRUE(o.report.poisoned.empty());
    EXPECT_EQ(o.image.width, 100);
    expectSameHits(ref, o.image.hits);
    EXPECT_NE(o.report.toJson().find("\"pixels_hit\""), std::string::npos);
  }
  expectSameHits(ref, runJob(j, fast(2, 64)).image.hits);
  expectSameHits(ref, runJob(j, fast(2, 96)).image.hits);
}

// Bricks that would cut the image's tiles are refused before anything runs; a worker handed
// such a region anyway (a forged task) fails it with the reason.
TEST(RenderFarm, BricksThatCutTilesAreRefused) {
  EXPECT_THROW(runJob(renderJob(64, 64), fast(0, 16)), std::invalid_argument);
  const JobSpec j = renderJob(64, 64);
  try {
    computeBrick(compileJobModel(j), j, {16, 0, 0}, {48, 32, 1}, 1);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("is not made of whole 32-pixel tiles"), std::string::npos) << e.what();
  }
}

TEST(RenderFarm, TileCodecRoundTripsAndRejectsMalformedInput) {
  BrickOutput in;
  in.tileLo = {32, 0, 0}, in.tileHi = {35, 2, 1};
  in.hits.resize(6);
  in.hits[1].kind = RayHit::kCentre, in.hits[1].depth = 2.5, in.hits[1].point = {1, 2, 3}, in.hits[1].normal = {0, 0, 1};
  in.hits[4].kind = RayHit::kFootprint, in.hits[4].depth = 3.25, in.hits[4].point = {-1, 0.5, 1e-300};
  const std::string s = encodePayload(Operation::Render, in);
  BrickOutput out;
  std::string err;
  ASSERT_TRUE(decodePayload(Operation::Render, s.data(), s.size(), out, &err)) << err;
  EXPECT_EQ(out.tileLo, in.tileLo);
  EXPECT_EQ(out.tileHi, in.tileHi);
  expectSameHits(in.hits, out.hits);
  for (size_t n = 0; n < s.size(); ++n) {  // every truncation
    std::string cut = s.substr(0, n);
    EXPECT_FALSE(decodeRenderTile(cut.data(), cut.size(), out, &err)) << n;
  }
  std::string extra = s + "x";
  EXPECT_FALSE(decodeRenderTile(extra.data(), extra.size(), out, &err));
  EXPECT_EQ(err, "render payload: trailing bytes");
  std::string kind = s;
  kind[4 + 24] = 7;  // the first pixel's kind
  EXPECT_FALSE(decodeRenderTile(kind.data(), kind.size(), out, &err));
  EXPECT_EQ(err, "render payload: unknown hit kind");
  std::string nan = s;
  const double q = std::nan("");
  std::memcpy(&nan[4 + 24 + 1 + 1], &q, 8);  // the second pixel's depth
  EXPECT_FALSE(decodeRenderTile(nan.data(), nan.size(), out, &err));
  EXPECT_EQ(err, "render payload: non-finite hit");
  std::string huge = s;
  const int32_t big = 1 << 30;
  std::memcpy(&huge[4 + 12], &big, 4);  // tileHi x: a region far beyond the payload
  EXPECT_FALSE(decodeRenderTile(huge.data(), huge.size(), out, &err));
  EXPECT_EQ(err, "render payload: region exceeds its size");
}
