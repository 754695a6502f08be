// frep slice --mask, which evaluates in float with the certified double fallback
// (PlaneOptions::floatSigns): on a model whose pixels lie exactly on the surface (a circle and a
// diagonal on a dyadic lattice, f = 0 there in both precisions), every pixel is white exactly
// where the closed form gives f >= 0.
#include <png.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "frep_runner.h"

using namespace frep_cli_test;

namespace {

std::vector<uint8_t> readRgb(const std::string& path, unsigned& width, unsigned& height) {
  png_image info;
  std::memset(&info, 0, sizeof info);
  info.version = PNG_IMAGE_VERSION;
  std::vector<uint8_t> rgb;
  if (!png_image_begin_read_from_file(&info, path.c_str())) {
    ADD_FAILURE() << "cannot read " << path << ": " << info.message;
    return rgb;
  }
  info.format = PNG_FORMAT_RGB;
  width = info.width, height = info.height;
  rgb.resize(PNG_IMAGE_SIZE(info));
  EXPECT_TRUE(png_image_finish_read(&info, nullptr, rgb.data(), 0, nullptr));
  return rgb;
}

}  // namespace

TEST_F(FrepTest, SliceMaskIsExactOnPixelsOnTheSurface) {
  // Inside: the disc of radius 1/2, and the half-plane x >= y beyond it (max = union).
  write(
      "c.hf",
      "my_model(x[3], a[1]) { my_model = max(0.25 - x[1]^2 - x[2]^2, min(x[1] - x[2], x[1]^2 + x[2]^2 - 0.5625)); }\n");
  RunResult r = run("slice c.hf -b 1 -g 128 --mask -O c.png");
  ASSERT_EQ(r.code, 0) << r.err;
  unsigned w = 0, h = 0;
  const std::vector<uint8_t> rgb = readRgb(path("c.png"), w, h);
  ASSERT_EQ(w, 129u);
  ASSERT_EQ(h, 129u);
  size_t wrong = 0, onSurface = 0;
  for (unsigned row = 0; row < h; ++row)
    for (unsigned col = 0; col < w; ++col) {
      // pixel centres -1 + k/64: every value below is exact in double
      const double x = -1.0 + col / 64.0, y = 1.0 - row / 64.0;
      const double disc = 0.25 - x * x - y * y, ring = x * x + y * y - 0.5625;
      const double f = std::max(disc, std::min(x - y, ring));
      onSurface += f == 0.0;
      const uint8_t expected = f >= 0 ? 255 : 0;
      wrong += rgb[(size_t(row) * w + col) * 3] != expected;
    }
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(onSurface, 8u);  // the test's point: pixels with f = 0 exactly
}
