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

// The farm: the image's tiles run as bricks on worker processes; the PNG bytes are the same
// in-process, on one worker and on two, and for any tile size (bricks of whole 32-pixel tiles).
TEST_F(FrepTest, RenderPngBytesIdenticalForWorkers012) {
  write("chair.hf", readText(FREP_EXAMPLES_DIR "/chair.hf"));
  const std::string common = "render chair.hf -b -1.5,-1.5,-0.5,1.5,1.5,2.5 --size 150x110 --perspective";
  RunResult r0 = run(common + " --workers 0 -O w0.png");
  ASSERT_EQ(r0.code, 0) << r0.err;
  EXPECT_TRUE(contains(r0.out, "tiles on the master (in-process)")) << r0.out;
  RunResult r1 = run(common + " --workers 1 -O w1.png");
  ASSERT_EQ(r1.code, 0) << r1.err;
  RunResult r2 = run(common + " --workers 2 --brick 32 -O w2.png");
  ASSERT_EQ(r2.code, 0) << r2.err;
  EXPECT_TRUE(contains(r2.out, "20 tiles on 2 workers")) << r2.out;  // ceil(150/32) x ceil(110/32)
  const std::string a = readText(path("w0.png"));
  EXPECT_GT(a.size(), 1000u);
  EXPECT_EQ(a, readText(path("w1.png")));
  EXPECT_EQ(a, readText(path("w2.png")));
  EXPECT_EQ(listing(), "chair.hf w0.png w1.png w2.png");  // no journal or report left behind
}

// Geometric types V and W: a 5D ball drawn as a 3x2 grid of its 3D sections at x[4] = v,
// x[5] = w; each cell's disc has radius sqrt(1 - v^2 - w^2) (one view for all cells).
TEST_F(FrepTest, RenderVWGridCellsAreTheAnalyticSections) {
  write("b5.hf", "b5(x[5], a[1]) { b5 = 1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3] - x[4]*x[4] - x[5]*x[5]; }\n");
  RunResult r = run("render b5.hf -x X,Y,Z,V,W --v-range -0.6,0.6 --v-cells 3 --w-range 0,0.5 --w-cells 2 -b 2 "
                    "--size 80x64 --no-footprint --background 0,0,0 --azimuth -90 --elevation 0 -O grid.png");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "3x2 cells")) << r.out;
  const Image img = readImage(path("grid.png"));
  ASSERT_EQ(img.width, 3u * 80 + 2 * 2);
  ASSERT_EQ(img.height, 2u * 64 + 2);
  const double step = pixelStep(r.out);
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 3; ++col) {
      size_t n = 0;
      for (unsigned y = 0; y < 64; ++y)
        for (unsigned x = 0; x < 80; ++x) {
          const size_t i = ((size_t(row) * 66 + y) * img.width + size_t(col) * 82 + x) * 3;
          n += img.rgb[i] || img.rgb[i + 1] || img.rgb[i + 2];
        }
      const double v = -0.6 + 0.6 * col, w = 0.5 * row, disc = M_PI * (1 - v * v - w * w) / (step * step);
      EXPECT_NEAR(double(n), disc, 0.02 * disc + 4) << "cell v " << v << " w " << w;
    }
}

// Geometric type C: a ball moving along x with x[4] drawn as the union of 5 sections, each in
// its spectral colour: red at c = -1, green in the middle, blue-violet at c = 1.
TEST_F(FrepTest, RenderColourSectionsAreSpectral) {
  write("mv.hf", "mv(x[4], a[1]) { mv = 0.25 - (x[1]-x[4])*(x[1]-x[4]) - x[2]*x[2] - x[3]*x[3]; }\n");
  RunResult r = run("render mv.hf -x X,Y,Z,C --c-range -1,1 --c-levels 5 -b 2 --size 241x121 --azimuth -90 "
                    "--elevation 0 -O c.png");
  ASSERT_EQ(r.code, 0) << r.err;
  const Image img = readImage(path("c.png"));
  const double step = pixelStep(r.out);
  auto dominant = [&](double x) {  // the strongest channel at the ball centre's pixel
    const size_t col = size_t(std::lround(x / step + 120)), i = (60 * size_t(img.width) + col) * 3;
    return int(std::max_element(&img.rgb[i], &img.rgb[i + 3]) - &img.rgb[i]);
  };
  EXPECT_EQ(dominant(-1), 0);
  EXPECT_EQ(dominant(0), 1);
  EXPECT_EQ(dominant(1), 2);
}

// Geometric type G: the ball moving along x with x[4] at the listed values -1, 0.2, 1 in one
// picture. The shaded pixels are the union of three discs of radius 0.5 (the last two overlap in
// a lens), each drawn in the spectral colour of its index; slice --mask of the same sections
// covers the same union in the plane z = 0.
TEST_F(FrepTest, RenderAndSliceGroupSectionsAreTheirUnion) {
  write("mv.hf", "mv(x[4], a[1]) { mv = 0.25 - (x[1]-x[4])*(x[1]-x[4]) - x[2]*x[2] - x[3]*x[3]; }\n");
  const double r = 0.5, d = 0.8;  // radius; distance of the discs at 0.2 and 1
  const double lens = 2 * r * r * std::acos(d / (2 * r)) - 0.5 * d * std::sqrt(4 * r * r - d * d);
  const double unionArea = 3 * M_PI * r * r - lens;
  RunResult rr = run("render mv.hf -x X,Y,Z,G --g-values -1,0.2,1 -b 2 --size 241x121 --azimuth -90 --elevation 0 "
                     "--no-footprint --background 0,0,0 -O g.png");
  ASSERT_EQ(rr.code, 0) << rr.err;
  const Image img = readImage(path("g.png"));
  const double step = pixelStep(rr.out), pixels = unionArea / (step * step);
  EXPECT_NEAR(double(countNotBackground(img, 0, 0, 0)), pixels, 0.01 * pixels + 4);
  auto dominant = [&](double x) {  // the box of the union is centred on x = 0
    const size_t col = size_t(std::lround(x / step + 120)), i = (60 * size_t(img.width) + col) * 3;
    return int(std::max_element(&img.rgb[i], &img.rgb[i + 3]) - &img.rgb[i]);
  };
  EXPECT_EQ(dominant(-1), 0);  // first value: red
  EXPECT_EQ(dominant(0.1), 1);  // middle: green
  EXPECT_EQ(dominant(1.1), 2);  // last: blue-violet
  RunResult sr = run("slice mv.hf -x X,Y,Z,G --g-values -1,0.2,1 -b 2 --res 201 --mask -O s.png");
  ASSERT_EQ(sr.code, 0) << sr.err;
  const Image mask = readImage(path("s.png"));
  ASSERT_EQ(mask.width, 201u);
  size_t inside = 0;
  for (size_t i = 0; i < mask.rgb.size(); i += 3) inside += mask.rgb[i] == 255;
  const double cells = unionArea / (0.02 * 0.02);  // 4 / 200 per pixel
  EXPECT_NEAR(double(inside), cells, 0.01 * cells + 4);
}

// frep slice with geometric types: numbered T frames, a V/W grid of sections (in --mask mode
// the inside pixels of each cell count the disc of radius sqrt(1 - v^2)), and the errors.
TEST_F(FrepTest, SliceGeometricTypes) {
  write("b4.hf", "b4(x[4], a[1]) { b4 = 1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3] - x[4]*x[4]; }\n");
  RunResult r = run("slice b4.hf -x X,Y,Z,T --t-frames 2 -b 2 --res 16 -O t.png");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(listing(), "b4.hf t_0000.png t_0001.png");
  r = run("slice b4.hf -x X,Y,Z,V --v-range 0,0.8 --v-cells 2 -b 1 --res 101 --mask -O v.png");
  ASSERT_EQ(r.code, 0) << r.err;
  const Image img = readImage(path("v.png"));
  ASSERT_EQ(img.width, 2u * 101 + 2);
  const double step = 2.0 / 100;
  for (int col = 0; col < 2; ++col) {
    size_t n = 0;
    for (unsigned y = 0; y < img.height; ++y)
      for (unsigned x = 0; x < 101; ++x) n += img.rgb[(size_t(y) * img.width + size_t(col) * 103 + x) * 3] == 255;
    const double v = 0.8 * col, disc = M_PI * (1 - v * v) / (step * step);
    EXPECT_NEAR(double(n), disc, 0.02 * disc + 4) << "v " << v;
  }
  struct Case { const char* args; const char* message; };
  const Case cases[] = {
      {"slice b4.hf -x X,Y,Z,T -O a.png", "--t-frames: the T coordinate needs the number of frames"},
      {"render b4.hf -x X,Y,C,G --g-values 1 -O a.png", "-x/--map: C and G both make a union of sections"},
      {"render b4.hf -x X,Y,Z,T,T --t-frames 2 -O a.png", "-x/--map: geometric type T is given twice"},
      {"slice b4.hf --g-values 1,2 -O a.png", "--g-values: give G in -x"},
      {"render b4.hf -x X,Y,Z,V --v-cells 0 -O a.png", "--v-range/--v-cells: expected a count from 1"},
      {"render b4.hf -x X,Y,Z,C --c-range 1 -O a.png", "--c-range/--c-levels: expected first,last"},
      {"render b4.hf --brick 48 -O a.png", "--brick: a render's bricks are tiles of whole 32-pixel squares"},
      {"render b4.hf --resume -O a.png", "--resume: a render keeps no journal"},
  };
  for (const Case& c : cases) {
    RunResult e = run(c.args);
    EXPECT_EQ(e.code, 2) << c.args << "\n" << e.err;
    EXPECT_TRUE(contains(e.err, c.message)) << c.args << "\n" << e.err;
  }
}

// Meshes and sampled grids are drawn by the z-buffer with the same view: the sphere's mesh
// (PLY, OBJ, STL from frep mesh) and its .vdb (frep sample) cover the model's disc to within
// the mesh's chordal error (under 1% of the area at -g 48).
TEST_F(FrepTest, RenderOfMeshesAndVdbMatchesTheModel) {
  write("s.hf", kSphere);
  const std::string view = " --size 160x160 --no-footprint --background 0,0,0 --azimuth -90 --elevation 0 --distance 4";
  RunResult model = run("render s.hf -b 2 -O model.png" + view);
  ASSERT_EQ(model.code, 0) << model.err;
  const double reference = double(countNotBackground(readImage(path("model.png")), 0, 0, 0));
  ASSERT_EQ(run("mesh s.hf -b 1.2 -g 48 --workers 0 -O s.ply").code, 0);
  ASSERT_EQ(run("mesh s.hf -b 1.2 -g 48 --workers 0 -O s.obj").code, 0);
  ASSERT_EQ(run("mesh s.hf -b 1.2 -g 48 --workers 0 -O s.stl").code, 0);
  ASSERT_EQ(run("sample s.hf -b 1.2 --res 48 --workers 0 -O s.vdb").code, 0);
  const std::string meshView = " --size 160x160 --background 0,0,0 --azimuth -90 --elevation 0 --distance 4";
  for (const char* input : {"s.ply", "s.obj", "s.stl", "s.vdb"}) {
    // The mesh's box is within a voxel of the model's, so fit the same view by the zoom the
    // model's fitted box gives: compare areas in units of each picture's own pixel.
    RunResult r = run(std::string("render ") + input + " -O m.png" + meshView);
    ASSERT_EQ(r.code, 0) << input << "\n" << r.err;
    EXPECT_TRUE(contains(r.out, "triangles")) << r.out;
    const double step = pixelStep(r.out), disc = M_PI / (step * step);
    EXPECT_NEAR(double(countNotBackground(readImage(path("m.png")), 0, 0, 0)), disc, 0.01 * disc) << input;
  }
  EXPECT_NEAR(reference, M_PI / std::pow(pixelStep(model.out), 2), 0.005 * M_PI / std::pow(pixelStep(model.out), 2));
  write("bad.stl", "solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n endloop\n endfacet\nendsolid\n");
  RunResult bad = run("render bad.stl -O b.png");
  EXPECT_EQ(bad.code, 3) << bad.err;
  EXPECT_TRUE(contains(bad.err, "bad.stl:6: a facet with fewer than 3 vertices")) << bad.err;
  RunResult opt = run("render s.ply -b 2 -O b.png");
  EXPECT_EQ(opt.code, 2);
  EXPECT_TRUE(contains(opt.err, "-b/--bounds: 's.ply' is a mesh or grid")) << opt.err;
}

// HyperFun's attributes colour the picture: hfA_SetColor's red on the sphere's left half and
// blue on its right (s[1..3] as hfp's VRML colours), the same for 0 and 2 workers.
TEST_F(FrepTest, RenderColoursByTheModelsAttributes) {
  write("c.hf", R"(my_model(x[3], a[1], s[3]) {
    r = 1 - x[1]*x[1] - x[2]*x[2] - x[3]*x[3];
    d = hfA_SetColor(r, s, 1, 0, 0);
    d = hfA_SetColor(x[1], s, 0, 0, 1);
    my_model = r;
  })");
  for (const char* workers : {"0", "2"}) {
    RunResult r = run(std::string("render c.hf -b 2 --size 120x120 --azimuth -90 --elevation 0 --background 0,0,0 "
                                  "--no-footprint --workers ") + workers + " -O c" + workers + ".png");
    ASSERT_EQ(r.code, 0) << r.err;
  }
  Image img = readImage(path("c0.png"));
  ASSERT_EQ(img.width, 120u);
  // Looking along +y (azimuth -90: the eye on -y), x grows to the right of the image.
  size_t redLeft = 0, blueRight = 0, hitLeft = 0, hitRight = 0;
  for (unsigned y = 0; y < img.height; ++y)
    for (unsigned x = 0; x < img.width; ++x) {
      const uint8_t* p = &img.rgb[(size_t(y) * img.width + x) * 3];
      if (p[0] == 0 && p[1] == 0 && p[2] == 0) continue;
      if (x < 50) ++hitLeft, redLeft += p[0] > 0 && p[1] == 0 && p[2] == 0;
      if (x > 70) ++hitRight, blueRight += p[2] > 0 && p[0] == 0 && p[1] == 0;
    }
  EXPECT_GT(hitLeft, 500u);
  EXPECT_EQ(redLeft, hitLeft);
  EXPECT_GT(hitRight, 500u);
  EXPECT_EQ(blueRight, hitRight);
  EXPECT_EQ(readText(path("c0.png")), readText(path("c2.png")));
}

}  // namespace
}  // namespace frep_cli_test

