// Heat map colours, contour placement, and the PNG round trip through libpng.
#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <cmath>
#include <cstring>

#include "frep/io/heatmap.h"
#include "frep/io/png_writer.h"


using namespace frep::io;

TEST(Heatmap, RampsAreWarmInsideCoolOutsideAndDarkenWithDepth) {
  for (double t : {0.0, 0.3, 0.7, 1.0}) {
    auto in = rampColour(true, t), out = rampColour(false, t);
    EXPECT_GT(in[0], in[2]) << t;
    EXPECT_GT(out[2], out[0]) << t;
  }
  auto sum = [](std::array<uint8_t, 3> c) { return c[0] + c[1] + c[2]; };
  EXPECT_GT(sum(rampColour(true, 0.0)), sum(rampColour(true, 1.0)));
  EXPECT_GT(sum(rampColour(false, 0.0)), sum(rampColour(false, 1.0)));
}

TEST(Heatmap, RobustScaleIgnoresTheTopFivePercent) {
  std::vector<double> m;
  for (int i = 1; i <= 100; ++i) m.push_back(i);
  m.back() = 1e12;
  EXPECT_EQ(robustScale(m), 95.0);  // index 0.95 * 99 = 94 -> value 95
  EXPECT_EQ(robustScale({}), 1.0);
  EXPECT_EQ(robustScale({0.0, 0.0}), 1.0);
}

TEST(Heatmap, ContourMarksThePixelNearerToZero) {
  // One row: f = 3, 1, -2, -4 -> the sign changes between pixels 1 and 2; |1| < |-2|.
  RgbImage img = renderHeatmap({3, 1, -2, -4, std::nan("")}, 5, 1);
  auto rgb = [&](int c) { uint8_t* p = img.pixel(c, 0); return std::array<int, 3>{p[0], p[1], p[2]}; };
  EXPECT_EQ(rgb(1), (std::array<int, 3>{0, 0, 0}));
  EXPECT_NE(rgb(2), (std::array<int, 3>{0, 0, 0}));
  EXPECT_GT(rgb(0)[0], rgb(0)[2]);  // warm
  EXPECT_GT(rgb(3)[2], rgb(3)[0]);  // cool
  EXPECT_EQ(rgb(4), (std::array<int, 3>{128, 128, 128}));  // NaN
}

TEST(PngWriter, RoundTripsThroughLibpng) {
  RgbImage img(3, 2);
  img.pixel(2, 1)[0] = 200;
  img.pixel(0, 0)[2] = 7;
  std::string path = testing::TempDir() + "png_writer_test_" + std::to_string(getpid()) + ".png";
  writePng(path, img);

  png_image info;
  std::memset(&info, 0, sizeof info);
  info.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&info, path.c_str())) << info.message;
  EXPECT_EQ(info.width, 3u);
  EXPECT_EQ(info.height, 2u);
  info.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> back(PNG_IMAGE_SIZE(info));
  ASSERT_TRUE(png_image_finish_read(&info, nullptr, back.data(), 0, nullptr));
  EXPECT_EQ(back, img.rgb);
  std::remove(path.c_str());
}

TEST(PngWriter, UnwritablePathIsAnIoError) {
  try {
    writePng("/nonexistent-dir/x.png", RgbImage(1, 1));
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write PNG '/nonexistent-dir/x.png'"), std::string::npos);
  }
}
