// frep measure: certified mass properties of .hf models against closed forms (--json), the
// cut-by-the-box warning, the text output and bad arguments.
#include <cmath>
#include <nlohmann/json.hpp>

#include "frep_runner.h"

namespace frep_cli_test {
namespace {

constexpr double kPi = 3.14159265358979323846;

class FrepMeasure : public FrepTest {
 protected:
  nlohmann::json measure(const std::string& model, const std::string& args) {
    write("m.hf", model);
    RunResult r = run("measure m.hf " + args + " --json");
    EXPECT_EQ(r.code, 0) << r.err;
    // One JSON object on stdout, nothing else.
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    last = r;
    return nlohmann::json::parse(r.out);
  }
  RunResult last;
};

void expectHolds(const nlohmann::json& b, double exact, double maxRelWidth, const char* what) {
  const double lo = b["lower"].get<double>(), hi = b["upper"].get<double>();
  EXPECT_LE(lo, exact) << what;
  EXPECT_GE(hi, exact) << what;
  if (maxRelWidth > 0) EXPECT_LE(hi - lo, maxRelWidth * std::fabs(exact)) << what << " [" << lo << ", " << hi << "]";
}

const char* kBall =
    "my_model(x[3], a[1]) {\n"
    "  array c[3];\n"
    "  c = [0.3, -0.2, 0.15];\n"
    "  my_model = hfSphere(x, c, 0.8);\n"
    "}\n";

TEST_F(FrepMeasure, BallVolumeAreaCentroidInertia) {
  nlohmann::json j = measure(kBall, "-b 1.5");
  const double r = 0.8, V = 4.0 / 3.0 * kPi * r * r * r;
  expectHolds(j["volume"], V, 0.005, "volume");
  expectHolds(j["area"], 4 * kPi * r * r, 0.005, "area");
  const double c[3] = {0.3, -0.2, 0.15};
  for (int i = 0; i < 3; ++i) expectHolds(j["centroid"][i], c[i], 0, "centroid");
  EXPECT_EQ(j["inertia_about"], "centroid");
  for (int i = 0; i < 3; ++i) {
    expectHolds(j["inertia"][i][i], 0.4 * V * r * r, 0.02, "inertia");
    for (int k = 0; k < 3; ++k)
      if (k != i) expectHolds(j["inertia"][i][k], 0.0, 0, "inertia");
  }
  // About the origin: parallel axes, I_o = I_c + V (|c|^2 E - c c^T).
  const double c2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      expectHolds(j["inertia_origin"][i][k], (i == k ? 0.4 * V * r * r : 0.0) + V * ((i == k ? c2 : 0.0) - c[i] * c[k]),
                  0, "inertia about the origin");
  EXPECT_TRUE(j["tolerance_reached"].get<bool>());
  EXPECT_TRUE(j["cut_faces"].empty());
  EXPECT_EQ(last.err.find("warn"), std::string::npos) << last.err;
}

TEST_F(FrepMeasure, MinkowskiSumOfABlockAndABallMatchesSteiner) {
  const double a = 0.6, b = 0.4, c = 0.8, r = 0.25;
  nlohmann::json j = measure(
      "blk(x[3], a[1]) {\n  array v[3];\n  v = [-0.3, -0.2, -0.4];\n  blk = hfBlock(x, v, 0.6, 0.4, 0.8);\n}\n"
      "ball(x[3], a[1]) {\n  array c[3];\n  c = [0, 0, 0];\n  ball = hfSphere(x, c, 0.25);\n}\n"
      "my_model(x[3], a[1]) {\n  my_model = frMinkowski(x, blk, ball);\n}\n",
      "-b 1.5");
  expectHolds(j["volume"],
              a * b * c + 2 * (a * b + b * c + c * a) * r + kPi * (a + b + c) * r * r + 4.0 / 3.0 * kPi * r * r * r,
              0.005, "volume");
  expectHolds(j["area"], 2 * (a * b + b * c + c * a) + 2 * kPi * (a + b + c) * r + 4 * kPi * r * r, 0.005, "area");
  for (int i = 0; i < 3; ++i) expectHolds(j["centroid"][i], 0.0, 0, "centroid");
}

TEST_F(FrepMeasure, ProjectionOfA4DBallIsA3DBall) {
  nlohmann::json j = measure(
      "ball4(x[4], a[1]) {\n  ball4 = 0.49 - (x[1] - 0.1)^2 - x[2]^2 - (x[3] + 0.1)^2 - (x[4] - 0.2)^2;\n}\n"
      "my_model(x[3], a[1]) {\n  my_model = frProject(x, ball4, 4);\n}\n",
      "-b 1.5");
  const double r = 0.7;
  expectHolds(j["volume"], 4.0 / 3.0 * kPi * r * r * r, 0.005, "volume");
  expectHolds(j["area"], 4 * kPi * r * r, 0.005, "area");
}

TEST_F(FrepMeasure, ASolidCutByTheBoxIsMeasuredInsideItWithAWarning) {
  nlohmann::json j = measure(
      "my_model(x[3], a[1]) {\n  array c[3];\n  c = [0, 0, 0];\n  my_model = hfSphere(x, c, 1);\n}\n",
      "-b -1.5,-1.5,0,1.5,1.5,1.5");
  expectHolds(j["volume"], 2.0 / 3.0 * kPi, 0.005, "half ball");
  expectHolds(j["area"], 3 * kPi, 0.005, "half ball's area, disc included");
  expectHolds(j["cut_area"], kPi, 0.005, "the disc");
  ASSERT_EQ(j["cut_faces"].size(), 1u);
  EXPECT_EQ(j["cut_faces"][0], "z-min");
  EXPECT_NE(last.err.find("z-min"), std::string::npos) << last.err;
  expectHolds(j["centroid"][2], 3.0 / 8.0, 0, "centroid z");
}

TEST_F(FrepMeasure, TextOutputAndTheSameNumbersForAnyThreadCount) {
  write("m.hf", kBall);
  RunResult t = run("measure m.hf -b 1.5 --no-progress");
  ASSERT_EQ(t.code, 0) << t.err;
  for (const char* key : {"volume:", "area:", "centroid: x", "inertia about the centroid", "I_xx:", "inertia about the origin"})
    EXPECT_NE(t.out.find(key), std::string::npos) << key << "\n" << t.out;
  RunResult one = run("measure m.hf -b 1.5 --json --threads 1");
  RunResult two = run("measure m.hf -b 1.5 --json --threads 2");
  ASSERT_EQ(one.code, 0) << one.err;
  ASSERT_EQ(two.code, 0) << two.err;
  nlohmann::json a = nlohmann::json::parse(one.out), b = nlohmann::json::parse(two.out);
  for (const char* key : {"volume", "area", "centroid", "inertia", "inertia_origin", "cells"}) EXPECT_EQ(a[key], b[key]) << key;
}

TEST_F(FrepMeasure, BadArguments) {
  write("m.hf", kBall);
  EXPECT_EQ(run("measure m.hf --tolerance 0").code, 2);
  EXPECT_EQ(run("measure m.hf --tolerance 2").code, 2);
  EXPECT_EQ(run("measure m.hf -b 1,1").code, 2);
  EXPECT_EQ(run("measure missing.hf").code, 3);
  write("flat.hf", "my_model(x[2], a[1]) { my_model = 1 - x[1]^2 - x[2]^2; }\n");
  RunResult flat = run("measure flat.hf");
  EXPECT_EQ(flat.code, 2);
  EXPECT_NE(flat.err.find("3D"), std::string::npos) << flat.err;
  RunResult j = run("measure flat.hf --json");
  EXPECT_EQ(j.code, 2);
  EXPECT_NE(j.out.find("\"event\":\"error\""), std::string::npos) << j.out;
}

}  // namespace
}  // namespace frep_cli_test
