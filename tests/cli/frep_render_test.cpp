// frep render end to end: the picture of a sphere against the analytic disc, identical bytes for
// any thread count, numbered frames, and the error messages.
#include <png.h>

#include <cmath>
#include <cstring>
#include <regex>
#include <vector>

#include "frep_runner.h"

namespace frep_cli_test {
namespace {

struct Image {
  unsigned width = 0, height = 0;
  std::vector<uint8_t> rgb;
};

Image readImage(const std::string& path) {
  png_image info;
  std::memset(&info, 0, sizeof info);
  info.version = PNG_IMAGE_VERSION;
  Image img;
  if (!png_image_begin_read_from_file(&info, path.c_str())) {
    ADD_FAILURE() << "cannot read " << path << ": " << info.message;
    return img;
  }
  info.format = PNG_FORMAT_RGB;
  img.width = info.width, img.height = info.height;
  img.rgb.resize(PNG_IMAGE_SIZE(info));
  EXPECT_TRUE(png_image_finish_read(&info, nullptr, img.rgb.data(), 0, nullptr));
  return img;
}

size_t countNotBackground(const Image& img, uint8_t r, uint8_t g, uint8_t b) {
  size_t n = 0;
  for (size_t i = 0; i + 2 < img.rgb.size(); i += 3)
    n += !(img.rgb[i] == r && img.rgb[i + 1] == g && img.rgb[i + 2] == b);
  return n;
}

double pixelStep(const std::string& out) {
  std::smatch m;
  if (!std::regex_search(out, m, std::regex("pixel ([0-9.e+-]+)"))) {
    ADD_FAILURE() << "no pixel size in: " << out;
    return 1;
  }
  return std::stod(m[1]);
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// Centre rays only: the shaded pixels are those whose ray meets the unit sphere, whose count is
// the disc's area in pixels.
TEST_F(FrepTest, RenderedSphereCoversTheAnalyticDisc) {
  write("s.hf", kSphere);
  for (const char* projection : {"", " --perspective --distance 4 --fov 40"}) {
    RunResult r = run(std::string("render s.hf -b 2 --size 240x200 --background 0,0,0 --no-footprint -O s.png") + projection);
    ASSERT_EQ(r.code, 0) << r.err;
    const Image img = readImage(path("s.png"));
    ASSERT_EQ(img.width, 240u);
    ASSERT_EQ(img.height, 200u);
    const double step = pixelStep(r.out);
    // Perspective (tangent units): the silhouette cone has tan = R / sqrt(D^2 - R^2).
    const double radius = *projection ? 1.0 / std::sqrt(15.0) : 1.0;
    const double disc = M_PI * radius * radius / (step * step);
    EXPECT_NEAR(double(countNotBackground(img, 0, 0, 0)), disc, 0.005 * disc) << projection << "\n" << r.out;
  }
}

TEST_F(FrepTest, RenderBytesDoNotDependOnTheThreadCount) {
  write("chair.hf", readText(FREP_EXAMPLES_DIR "/chair.hf"));
  const std::string common = "render chair.hf -b -1.5,-1.5,-0.5,1.5,1.5,2.5 --size 160x120 --perspective";
  ASSERT_EQ(run(common + " --threads 1 -O a.png").code, 0);
  ASSERT_EQ(run(common + " --threads 2 -O b.png").code, 0);
  ASSERT_EQ(run(common + " -O c.png").code, 0);
  const std::string a = readText(path("a.png"));
  EXPECT_GT(a.size(), 1000u);
  EXPECT_EQ(a, readText(path("b.png")));
  EXPECT_EQ(a, readText(path("c.png")));
}

TEST_F(FrepTest, RenderWritesNumberedFrames) {
  write("s.hf", kSphere);
  RunResult r = run("render s.hf -b 2 --size 32x32 --frames 3 -O turn.png");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(listing(), "s.hf turn_0000.png turn_0001.png turn_0002.png");
  // A 4D ball: the section at x[4] = t has radius sqrt(1 - t^2), so the disc shrinks over frames.
  write("b4.hf", "b4(x[4], a[1]) { b4 = 1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3] - x[4]*x[4]; }\n");
  r = run("render b4.hf -b 2 --size 64x64 --zoom 0.5 --t-frames 3 --t-range 0,0.8 --no-footprint "
          "--azimuth -90 --elevation 0 -O t.png");
  ASSERT_EQ(r.code, 0) << r.err;
  // One view for all frames: the disc's pixel count goes with r^2 = 1 - t^2 (t = 0, 0.4, 0.8).
  std::vector<double> counts;
  for (int k = 0; k < 3; ++k) counts.push_back(double(countNotBackground(readImage(path("t_000" + std::to_string(k) + ".png")), 255, 255, 255)));
  const double step = pixelStep(r.out);
  for (int k = 0; k < 3; ++k) {
    const double t = 0.4 * k, disc = M_PI * (1 - t * t) / (step * step);
    EXPECT_NEAR(counts[size_t(k)], disc, 0.02 * disc + 4) << "frame " << k;
  }
}

TEST_F(FrepTest, RenderRejectsBadArgumentsBeforeWriting) {
  write("s.hf", kSphere);
  write("d2.hf", "d2(x[2], a[1]) { d2 = 1 - x[1]*x[1] - x[2]*x[2]; }\n");
  struct Case { const char* args; const char* message; };
  const Case cases[] = {
      {"render s.hf", "frep: error: -O/--out: the output PNG path is required"},
      {"render s.hf --size 10 -O a.png", "frep: error: --size: expected WxH"},
      {"render s.hf --background 1,2 -O a.png", "frep: error: --background: expected r,g,b"},
      {"render s.hf --colour 1,2,300 -O a.png", "frep: error: --colour: each of r,g,b must be in 0..255"},
      {"render s.hf --zoom 0 -O a.png", "frep: error: --zoom: expected a positive number"},
      {"render s.hf --t-frames 2 -O a.png", "frep: error: --t-frames: the object has no x[4] to sweep"},
      {"render s.hf --frames 2 --t-frames 2 -O a.png", "frep: error: --frames and --t-frames: give one of them"},
      {"render d2.hf -O a.png", "frep: error: render: the object is 2-dimensional"},
      {"render s.hf --eye 0,0,0 --target 0,0,0 -O a.png", "frep: error: --eye/--target: camera: the eye and the target coincide"},
  };
  for (const Case& c : cases) {
    RunResult r = run(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, c.message)) << c.args << "\n" << r.err;
  }
  EXPECT_EQ(listing(), "d2.hf s.hf");
}

}  // namespace
}  // namespace frep_cli_test
