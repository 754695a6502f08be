// frep relate: certified intersection, inclusion, clearance and penetration depth of two models,
// point membership.
#include <cmath>
#include <nlohmann/json.hpp>

#include "frep_runner.h"

namespace frep_cli_test {
namespace {

std::string ball(double cx, double r) {
  return "m(x[3], a[1]) { m = " + std::to_string(r * r) + " - (x[1] - (" + std::to_string(cx) +
         "))^2 - x[2]^2 - x[3]^2; }\n";
}
// Axis-aligned box [x0, x1] x [0, 1] x [0, 1] as an exact min of slabs.
std::string block(double x0, double x1) {
  return "m(x[3], a[1]) { m = min(min(x[1] - (" + std::to_string(x0) + "), " + std::to_string(x1) +
         " - x[1]), min(min(x[2], 1 - x[2]), min(x[3], 1 - x[3]))); }\n";
}

// The three numbers of "(a, b, c)" after `key`.
std::vector<double> pointAfter(const std::string& text, const std::string& key) {
  size_t at = text.find(key);
  std::vector<double> p;
  if (at == std::string::npos) return p;
  at = text.find('(', at);
  const char* s = text.c_str() + at + 1;
  for (int i = 0; i < 3; ++i) {
    char* end;
    p.push_back(std::strtod(s, &end));
    s = end + 1;
  }
  return p;
}

class FrepRelate : public FrepTest {};

TEST_F(FrepRelate, NestedBalls) {
  write("small.hf", ball(0.2, 1));
  write("big.hf", ball(0, 2));
  RunResult r = run("relate small.hf big.hf -b 3 --at 1.2,0,0 --distance-tol 0.05");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("point (1.2, 0, 0): on the surface A, inside B"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("intersect: yes, common point"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("A inside B: yes (proved in the box)"), std::string::npos) << r.out;
  // Penetration depth: the small ball leaves the big one after 2 + 1 - 0.2 = 2.8.
  size_t at = r.out.find("penetration: [");
  ASSERT_NE(at, std::string::npos) << r.out;
  char* end;
  const double lo = std::strtod(r.out.c_str() + at + 14, &end);
  const double hi = std::strtod(end + 1, nullptr);
  EXPECT_LE(lo, 2.8);
  EXPECT_GE(hi, 2.8);
  EXPECT_LE(hi - lo, 0.05);
  RunResult back = run("relate big.hf small.hf -b 3 --distance-tol 0.05");
  ASSERT_EQ(back.code, 0) << back.err;
  std::vector<double> w = pointAfter(back.out, "point of A not inside B");
  ASSERT_EQ(w.size(), 3u) << back.out;
  // The witness is in the big ball and not in the small one's interior.
  EXPECT_GE(4 - (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), 0);
  EXPECT_LE(1 - ((w[0] - 0.2) * (w[0] - 0.2) + w[1] * w[1] + w[2] * w[2]), 0);
}

TEST_F(FrepRelate, TouchingAndSeparatedBoxes) {
  write("a.hf", block(0, 1));
  write("touch.hf", block(1, 2));
  write("apart.hf", block(1.01, 2));
  RunResult t = run("relate a.hf touch.hf -b 3 --min-size 1e-3");
  ASSERT_EQ(t.code, 0) << t.err;
  // They share the face x = 1, which no sub-box centre hits (the box is ±3): undecided, never no.
  EXPECT_NE(t.out.find("intersect: undecided"), std::string::npos) << t.out;
  RunResult s = run("relate a.hf apart.hf -b 3 --min-size 1e-3");
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_NE(s.out.find("intersect: no (proved disjoint in the box)"), std::string::npos) << s.out;
}

// Two balls of radius 1.01 at x = -1 and 1 overlap in a lens 0.02 thick around x = 0. A 96^3
// grid over the box ±3 (spacing 6/95) has no point in both; the subdivision finds one.
TEST_F(FrepRelate, ThinOverlapAGridMisses) {
  auto fa = [](double x, double y, double z) { return 1.0201 - (x + 1) * (x + 1) - y * y - z * z; };
  auto fb = [](double x, double y, double z) { return 1.0201 - (x - 1) * (x - 1) - y * y - z * z; };
  int both = 0;
  for (int i = 0; i < 96; ++i)
    for (int j = 0; j < 96; ++j)
      for (int k = 0; k < 96; ++k) {
        double x = -3 + 6.0 * i / 95, y = -3 + 6.0 * j / 95, z = -3 + 6.0 * k / 95;
        both += fa(x, y, z) >= 0 && fb(x, y, z) >= 0;
      }
  EXPECT_EQ(both, 0);
  write("l.hf", ball(-1, 1.01));
  write("r.hf", ball(1, 1.01));
  RunResult r = run("relate l.hf r.hf -b 3");
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<double> w = pointAfter(r.out, "common point");
  ASSERT_EQ(w.size(), 3u) << r.out;
  // The printed witness (shortest round-trip digits) is in both balls.
  EXPECT_GE(fa(w[0], w[1], w[2]), -1e-12);
  EXPECT_GE(fb(w[0], w[1], w[2]), -1e-12);
  EXPECT_NE(r.out.find("A inside B: no"), std::string::npos) << r.out;
}

// Unit balls centred at x = -2 and x = 1.5: clearance 3.5 - 2 = 1.5, nearest points (-1, 0, 0)
// and (0.5, 0, 0).
TEST_F(FrepRelate, ClearanceOfTwoBallsWithinItsBound) {
  write("l.hf", ball(-2, 1));
  write("r.hf", ball(1.5, 1));
  RunResult r = run("relate l.hf r.hf -b 4 --distance-tol 1e-3 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["intersect"]["answer"], "no");
  const double lo = j["clearance"]["lower"], hi = j["clearance"]["upper"];
  // The witnesses are tested in double precision: the upper bound holds to rounding.
  EXPECT_LE(lo, 1.5);
  EXPECT_GE(hi, 1.5 - 1e-12);
  EXPECT_LE(hi - lo, 1e-3);
  EXPECT_TRUE(j["clearance"]["converged"].get<bool>());
  std::vector<double> a = j["clearance"]["witness_a"], b = j["clearance"]["witness_b"];
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), 3u);
  // The witnesses are points of their balls, hi apart.
  EXPECT_GE(1 - ((a[0] + 2) * (a[0] + 2) + a[1] * a[1] + a[2] * a[2]), 0);
  EXPECT_GE(1 - ((b[0] - 1.5) * (b[0] - 1.5) + b[1] * b[1] + b[2] * b[2]), 0);
  EXPECT_NEAR(std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]), hi, 1e-12);
  EXPECT_EQ(j["penetration"]["upper"], 0.0);
  RunResult t = run("relate l.hf r.hf -b 4 --distance-tol 1e-3");
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.out.find("clearance: ["), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("penetration: 0 (disjoint)"), std::string::npos) << t.out;
}

// The box [0, 1]^3 and the box [2, 3] x [2, 3] x [0, 1] are sqrt(2) apart (edge to edge).
TEST_F(FrepRelate, ClearanceOfBoxesAtAnOffset) {
  write("a.hf", block(0, 1));
  write("b.hf",
        "m(x[3], a[1]) { m = min(min(x[1] - 2, 3 - x[1]), min(min(x[2] - 2, 3 - x[2]), min(x[3], 1 - x[3]))); }\n");
  RunResult r = run("relate a.hf b.hf -b 4 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  const double lo = j["clearance"]["lower"], hi = j["clearance"]["upper"];
  EXPECT_LE(lo, std::sqrt(2.0));
  EXPECT_GE(hi, std::sqrt(2.0));
  EXPECT_LE(hi - lo, 8e-3);  // the default: 1e-3 of the box's edge
}

// A unit ball at the origin reaches 0.5 into the box [0.5, 3] x [-2, 2]^2: depth 0.5; A moved by
// the reported translation is clear of B.
TEST_F(FrepRelate, PenetrationOfBallIntoBox) {
  write("ball.hf", ball(0, 1));
  write("wall.hf",
        "m(x[3], a[1]) { m = min(min(x[1] - 0.5, 3 - x[1]), min(min(x[2] + 2, 2 - x[2]), min(x[3] + 2, "
        "2 - x[3]))); }\n");
  RunResult r = run("relate ball.hf wall.hf -b 4 --distance-tol 2e-3 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["intersect"]["answer"], "yes");
  EXPECT_EQ(j["clearance"]["upper"], 0.0);
  const double lo = j["penetration"]["lower"], hi = j["penetration"]["upper"];
  EXPECT_LE(lo, 0.5);
  EXPECT_GE(hi, 0.5);
  EXPECT_LE(hi - lo, 2e-3);
  std::vector<double> t = j["penetration"]["translation"];
  ASSERT_EQ(t.size(), 3u);
  // Moving the ball by t clears the wall: its centre ends at least 1 left of x = 0.5.
  EXPECT_LE(t[0], -0.5);
  EXPECT_NEAR(std::hypot(t[0], t[1], t[2]), hi, 1e-12);
}

TEST_F(FrepRelate, BadArguments) {
  write("a.hf", ball(0, 1));
  EXPECT_EQ(run("relate a.hf missing.hf").code, 3);
  RunResult r = run("relate a.hf a.hf --at 1,2");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--at"), std::string::npos) << r.err;
  RunResult d = run("relate a.hf a.hf --distance-tol -1");
  EXPECT_EQ(d.code, 2);
  EXPECT_NE(d.err.find("--distance-tol"), std::string::npos) << d.err;
}

}  // namespace
}  // namespace frep_cli_test
