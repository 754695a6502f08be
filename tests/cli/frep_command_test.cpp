// The frep binary end to end: exit codes, messages, eval values and slice images.
#include <png.h>

#include <cstring>
#include <vector>

#include "frep_runner.h"

using namespace frep_cli_test;

namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

struct Png {
  unsigned width = 0, height = 0;
  std::vector<uint8_t> rgb;
  const uint8_t* at(unsigned col, unsigned row) const { return &rgb[(size_t(row) * width + col) * 3]; }
};

Png readPng(const std::string& path) {
  png_image info;
  std::memset(&info, 0, sizeof info);
  info.version = PNG_IMAGE_VERSION;
  Png png;
  if (!png_image_begin_read_from_file(&info, path.c_str())) {
    ADD_FAILURE() << "cannot read " << path << ": " << info.message;
    return png;
  }
  info.format = PNG_FORMAT_RGB;
  png.width = info.width;
  png.height = info.height;
  png.rgb.resize(PNG_IMAGE_SIZE(info));
  EXPECT_TRUE(png_image_finish_read(&info, nullptr, png.rgb.data(), 0, nullptr));
  return png;
}

bool warm(const uint8_t* p) { return p[0] > p[2] + 40; }
bool cool(const uint8_t* p) { return p[2] > p[0] + 40; }
bool black(const uint8_t* p) { return p[0] == 0 && p[1] == 0 && p[2] == 0; }

const char* kTwoObjects =
    "Box(x[3], a[1]) { Box = 1 - abs(x[1]); }\n"
    "my_model(x[3], a[1])\n"
    "{\n"
    "  my_model = Box(x, a);\n"
    "}\n";

const char* kSyntaxError =
    "my_model(x[3], a[1])\n"
    "{\n"
    "  my_model = 1 - x[1] * ;\n"
    "}\n";

}  // namespace

TEST_F(FrepTest, HelpDocumentsExitCodes) {
  RunResult r = run("--help");
  EXPECT_EQ(r.code, 0);
  EXPECT_TRUE(contains(r.out, "Exit codes: 0 ok, 1 model error (diagnostics printed), 2 bad arguments, "
                              "3 I/O error, 4 internal error, 5 bricks poisoned (named), 6 interrupted (use "
                              "--resume), 7 farm error."))
      << r.out;
}

TEST_F(FrepTest, CheckListsObjectsAndTheSelectedOne) {
  write("two.hf", kTwoObjects);
  RunResult r = run("check two.hf");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "two.hf: ok, 2 objects")) << r.out;
  EXPECT_TRUE(contains(r.out, "  box(x[3], a[1])  line 1\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "  my_model(x[3], a[1])  line 2  (selected)\n")) << r.out;
  RunResult box = run("check two.hf -o Box");
  EXPECT_TRUE(contains(box.out, "  box(x[3], a[1])  line 1  (selected)\n")) << box.out;
}

TEST_F(FrepTest, SyntaxErrorGivesFileLineColumnAndExit1) {
  write("bad.hf", kSyntaxError);
  RunResult r = run("check bad.hf");
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(contains(r.err, "bad.hf:3:25: error:")) << r.err;
  EXPECT_TRUE(contains(r.err, "  my_model = 1 - x[1] * ;\n")) << r.err;
  EXPECT_TRUE(contains(r.err, "frep: error: bad.hf: ")) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST_F(FrepTest, ModelErrorLeavesNoOutputFile) {
  write("bad.hf", kSyntaxError);
  RunResult r = run("slice bad.hf --res 16 -O s.png");
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(listing(), "bad.hf");
}

TEST_F(FrepTest, MissingModelIsAnIoError) {
  RunResult r = run("check nothere.hf");
  EXPECT_EQ(r.code, 3);
  EXPECT_TRUE(contains(r.err, "frep: error: cannot read model 'nothere.hf': No such file or directory")) << r.err;
}

TEST_F(FrepTest, EvalSphereIsExact) {
  write("s.hf", kSphere);
  RunResult r = run("eval s.hf --at 0.5,0.25,0");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "object: my_model\nvalue: 0.6875\nstatus: in\ngradient: -1, -0.5, 0\n");

  RunResult withParam = run("eval s.hf --at -0.5,0.25,0 -a 1");  // radius 2
  EXPECT_EQ(withParam.out, "object: my_model\nvalue: 3.6875\nstatus: in\ngradient: 1, -0.5, 0\n") << withParam.err;

  RunResult on = run("eval s.hf --at 0,1,0");
  EXPECT_EQ(on.out, "object: my_model\nvalue: 0\nstatus: on\ngradient: 0, -2, 0\n");
  RunResult out = run("eval s.hf --at 0,0,2");
  EXPECT_EQ(out.out, "object: my_model\nvalue: -3\nstatus: out\ngradient: 0, 0, -4\n");
}

TEST_F(FrepTest, EvalIsovalueAndTolerance) {
  write("s.hf", kSphere);
  EXPECT_TRUE(contains(run("eval s.hf --at 0.5,0.25,0 -i 0.5").out, "value: 0.1875\nstatus: in\n"));
  // f(1.0000001, 0, 0) = -2.00000001e-7: outside by default, on with a looser tolerance.
  EXPECT_TRUE(contains(run("eval s.hf --at 1.0000001,0,0").out, "status: out\n"));
  EXPECT_TRUE(contains(run("eval s.hf --at 1.0000001,0,0 --tolerance 1e-6").out, "status: on\n"));
}

TEST_F(FrepTest, EvalMapsHigherCoordinatesWithX) {
  write("s4.hf", "my_model(x[4], a[1]) { my_model = 1 - x[1]^2 - x[2]^2 - x[3]^2 - x[4]^2; }\n");
  EXPECT_TRUE(contains(run("eval s4.hf --at 0,0,0,0.5").out, "value: 0.75\n"));
  RunResult mapped = run("eval s4.hf -x 0.5,Z,Y,X --at 0.25,0,0");  // x[4] = X = 0.25
  EXPECT_EQ(mapped.code, 0) << mapped.err;
  EXPECT_TRUE(contains(mapped.out, "value: 0.6875\n")) << mapped.out;
  RunResult wrong = run("eval s4.hf -x X,Y,Z --at 0,0,0");
  EXPECT_EQ(wrong.code, 2);
  EXPECT_TRUE(contains(wrong.err, "-x/--map: object 'my_model' has x[4], so -x needs 4 entries, got 'X,Y,Z'"))
      << wrong.err;
}

TEST_F(FrepTest, BadArgumentsNameTheField) {
  write("s.hf", kSphere);
  struct Case { const char* args; const char* message; };
  const Case cases[] = {
      {"eval s.hf --at 1,2", "frep: error: --at: expected 3 comma-separated numbers (one per coordinate of "
                             "'my_model'), got '1,2'"},
      {"eval s.hf --at a,0,0", "('a' is not a number)"},
      {"eval s.hf --at 0,0,0 -a 1,2", "frep: error: -a/--params: object 'my_model' has a[1], got 2 values in '1,2'"},
      {"slice s.hf -b a,b -O s.png",
       "frep: error: -b/--bounds: expected 1, 2, 3 or 6 comma-separated numbers, got 'a,b' ('a' is not a number)"},
      {"slice s.hf --axis w -O s.png", "frep: error: --axis: expected x, y or z, got 'w'"},
      {"slice s.hf --res 16 -g 8 -O s.png", "frep: error: --res and -g/--grid: give one of them, not both"},
      {"slice s.hf -o s.png", "frep: error: -o/--object: 's.png' looks like a file name; -o selects the object "
                              "(as in hfp), write files with -O/--out"},
      {"slice s.hf --res 16", "frep: error: -O/--out: the output PNG path is required"},
      {"sample s.hf --band 0 -O s.vdb", "frep: error: --band: expected an integer from 1 to 64 (voxels), got 0"},
      {"eval s.hf", "--at is required"},
      {"frob s.hf", "frep: error: unknown verb 'frob'; the verbs are check, eval, slice, sample, mesh, pov, relate, measure, render, view and keygen"},
      {"eval s.hf --at 0,0,0 --log-level loud", "--log-level"},
  };
  for (const Case& c : cases) {
    RunResult r = run(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, c.message)) << c.args << "\n" << r.err;
  }
  EXPECT_EQ(listing(), "s.hf");  // no output file was started
}

TEST_F(FrepTest, UnwritableOutputIsAnIoErrorAndLeavesNothing) {
  write("s.hf", kSphere);
  write("plain", "a file, not a directory\n");
  RunResult r = run("slice s.hf --res 16 -O plain/s.png");
  EXPECT_EQ(r.code, 3);
  EXPECT_TRUE(contains(r.err, "frep: error: -O/--out: cannot write 'plain/s.png': Not a directory")) << r.err;
  // The output is a directory: refused before any work (docs/cli.md: -O is new or a regular file).
  ASSERT_EQ(::mkdir(path("adir").c_str(), 0755), 0);
  RunResult dir = run("sample s.hf --res 16 -O adir");
  EXPECT_EQ(dir.code, 3) << dir.err;
  EXPECT_TRUE(contains(dir.err, "'adir' is a directory")) << dir.err;
  EXPECT_EQ(listing(), "adir plain s.hf");
}

TEST_F(FrepTest, SliceWritesAHeatMapOfTheRequestedSize) {
  write("s.hf", kSphere);
  RunResult r = run("slice s.hf -b 2 --res 64 -O s.png");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "wrote s.png: 64x64 pixels at z = 0")) << r.out;
  EXPECT_EQ(listing(), "s.hf s.png");
  Png png = readPng(path("s.png"));
  ASSERT_EQ(png.width, 64u);
  ASSERT_EQ(png.height, 64u);
  EXPECT_TRUE(warm(png.at(32, 32)));  // the centre is inside
  EXPECT_TRUE(cool(png.at(0, 0)));    // a corner is outside
  // Along the middle row the contour is crossed once on each side of the centre: |x| = 1 lies
  // between pixels 15 (x = -1.047) and 16 (x = -0.984); 16 is nearer to the surface.
  int blackCount = 0;
  for (unsigned c = 0; c < 64; ++c) blackCount += black(png.at(c, 32));
  EXPECT_EQ(blackCount, 2);
  EXPECT_TRUE(black(png.at(16, 32)));
}

TEST_F(FrepTest, SliceOfA2DObjectNeedsNoAxisAndKeepsTheAspect) {
  // The strip 0.5 <= x <= 1.5 of the plane.
  write("strip.hf", "my_model(x[2], a[1]) { my_model = 0.5 - abs(x[1] - 1); }\n");
  RunResult r = run("slice strip.hf -b 0,0,0,2,1,1 --res 33 -O strip.png");
  ASSERT_EQ(r.code, 0) << r.err;
  Png png = readPng(path("strip.png"));
  ASSERT_EQ(png.width, 33u);
  ASSERT_EQ(png.height, 17u);
  EXPECT_TRUE(warm(png.at(16, 8)));  // x = 1
  EXPECT_TRUE(cool(png.at(2, 8)));   // x = 0.125
  EXPECT_TRUE(cool(png.at(30, 8)));  // x = 1.875
}

TEST_F(FrepTest, SliceAlongXShowsTheYZPlane) {
  // A ball centred at (1, 0, 0.5): on the plane x = 1 its disc is centred at (y, z) = (0, 0.5).
  write("b.hf", "my_model(x[3], a[1]) { my_model = 0.25 - (x[1]-1)^2 - x[2]^2 - (x[3]-0.5)^2; }\n");
  RunResult r = run("slice b.hf --axis x --at 1 -b 1 -g 8 -O b.png");
  ASSERT_EQ(r.code, 0) << r.err;
  Png png = readPng(path("b.png"));
  ASSERT_EQ(png.width, 9u);
  ASSERT_EQ(png.height, 9u);
  // Columns are y = -1 + 0.25 c, rows go down from z = 1: (y, z) = (0, 0.5) is column 4, row 2.
  EXPECT_TRUE(warm(png.at(4, 2)));
  EXPECT_TRUE(cool(png.at(4, 6)));  // z = -0.5
}

// The .hf files directly in `dir`.
std::vector<std::string> hfFilesIn(const std::string& dir) {
  std::vector<std::string> models;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (dirent* e = ::readdir(d)) {
      std::string name = e->d_name;
      if (name.size() > 3 && name.compare(name.size() - 3, 3, ".hf") == 0) models.push_back(name);
    }
    ::closedir(d);
  }
  return models;
}

// Each checks with exit 0, one object and not even a warning (`run` is FrepTest::run).
template <typename Run>
void expectChecksCleanly(const Run& run, const std::string& dir, const std::vector<std::string>& models) {
  for (const std::string& m : models) {
    RunResult r = run("check '" + dir + "/" + m + "'");
    EXPECT_EQ(r.code, 0) << m << "\n" << r.err;
    EXPECT_EQ(r.err, "") << m;
    EXPECT_TRUE(contains(r.out, ": ok, 1 object")) << m << "\n" << r.out;
  }
}

TEST_F(FrepTest, EveryExampleChecksCleanly) {
  const std::vector<std::string> models = hfFilesIn(FREP_EXAMPLES_DIR);
  EXPECT_GE(models.size(), 5u);
  expectChecksCleanly([&](const std::string& a) { return run(a); }, FREP_EXAMPLES_DIR, models);
}

// examples/convolution/ (frConv<Kernel><Skeleton>, docs/language.md): every file checks without
// a warning, and a point each header describes is inside its solid and one is outside.
TEST_F(FrepTest, EveryConvolutionExampleChecksCleanly) {
  const std::string dir = FREP_EXAMPLES_DIR "/convolution";
  const std::vector<std::string> models = hfFilesIn(dir);
  EXPECT_GE(models.size(), 3u);
  expectChecksCleanly([&](const std::string& a) { return run(a); }, dir, models);
  struct Probe {
    const char* file;
    const char* at;
    bool in;
  };
  const Probe probes[] = {
      {"soft_letter.hf", "-0.4,-0.5,0", true},     // the stem (tube radius 0.15)
      {"soft_letter.hf", "-0.3,-0.5,0", false},
      {"soft_letter.hf", "0.4,0.5,0", true},       // the bowl's arc, at its right-most point
      {"soft_letter.hf", "0.1,0.5,0", false},      // the bowl's hole
      {"triangle_blob.hf", "0,0,0", true},         // the faces fill the inside
      {"triangle_blob.hf", "-0.7,-0.7,-0.7", false},  // the corner the tetrahedron does not have
      {"kernel_compare.hf", "-2.7,0.05,0", true},  // an arm in each panel
      {"kernel_compare.hf", "-0.3,0.05,0", true},
      {"kernel_compare.hf", "2.1,0.05,0", true},
      {"kernel_compare.hf", "-2.4,1,0", false},    // between the arms' tops
      {"kernel_compare.hf", "2.4,1,0", false},
      {"kernel_compare.hf", "0,-0.1,0", true},    // the inverse square webs the inner corner higher
      {"kernel_compare.hf", "2.4,-0.1,0", false},  // than the soft kernel (its web ends at y = -0.16)
  };
  for (const Probe& p : probes) {
    RunResult r = run("eval '" + dir + "/" + p.file + "' --at " + p.at);
    EXPECT_EQ(r.code, 0) << p.file << "\n" << r.err;
    EXPECT_TRUE(contains(r.out, p.in ? "status: in" : "status: out")) << p.file << " at " << p.at << "\n" << r.out;
  }
}

TEST_F(FrepTest, SliceHoldsHigherCoordinatesAtZeroOrAtTheirMapping) {
  // A 4D ball: at x[4] = 0 the slice z = 0 is the unit disc; at x[4] = 0.8 its radius is 0.6.
  write("s4.hf", "my_model(x[4], a[1]) { my_model = 1 - x[1]^2 - x[2]^2 - x[3]^2 - x[4]^2; }\n");
  RunResult r = run("slice s4.hf -b 1 -g 10 -O a.png");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "frep: warning: object 'my_model' has x[4]: x[4] and above are held at 0 "
                              "(choose with -x, e.g. -x X,Y,Z,0)"))
      << r.err;
  // Pixel (8, 5) is (x, y) = (0.6, 0): inside the unit disc.
  EXPECT_TRUE(warm(readPng(path("a.png")).at(8, 5)));
  RunResult mapped = run("slice s4.hf -b 1 -g 10 -x X,Y,Z,0.8 -O b.png");
  ASSERT_EQ(mapped.code, 0) << mapped.err;
  EXPECT_EQ(mapped.err, "");
  Png b = readPng(path("b.png"));
  EXPECT_TRUE(black(b.at(8, 5)));  // f = 0 exactly on the circle of radius 0.6
  EXPECT_TRUE(cool(b.at(9, 5)));
  EXPECT_TRUE(warm(b.at(7, 5)));
}

TEST_F(FrepTest, DomainErrorsAreReportedNotFatal) {
  // x^0.5 is NaN for x < 0 (core convention): eval says so, slice paints those pixels grey.
  write("n.hf", "my_model(x[3], a[1]) { my_model = 0.5 - x[1]^0.5; }\n");
  RunResult r = run("eval n.hf --at -1,0,0");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "value: nan\nstatus: out (NaN: a domain error, counted as outside)\n")) << r.out;
  RunResult s = run("slice n.hf -b 1 --res 16 -O n.png");
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_TRUE(contains(s.out, ", 128 NaN pixels (grey); evaluated 256 of 256 pixels")) << s.out;  // columns 0..7 of 16 rows
  Png png = readPng(path("n.png"));
  EXPECT_EQ(png.at(3, 3)[0], 128);
  EXPECT_EQ(png.at(3, 3)[2], 128);
}
