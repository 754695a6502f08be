// Vyatkin-Perturbation's claim (Collision detection): for perturbation freeforms, collision
// detection by recursive space subdivision takes the same time whatever the collision's
// complexity. Measured here with core mayIntersect (relations.h: interval bisection of the box,
// longest edge first, down to minSize) on two unit balls 0.05 apart, each carrying N bumps
// R_i = A_i max(Q_i, 0)^3 (eq. 10) with ellipsoidal quadrics Q_i: the bumps sit away from the
// gap (disjoint pairs), or k of them on each ball face the other and close the gap (k contact
// regions). Prints sub-boxes visited and CPU time per query, with the ratio to N = 0 measured in
// the same run. It never fails on time.
//
// Usage: bench_collision [--quick]
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "frep/relations/relations.h"

#include "bench_timing.h"

using namespace frep;

namespace {

struct Bump {
  double c[3], r, h;
};

// A unit ball at (cx, 0, 0) plus bumps: 1 - |X - C|^2 + sum h max(1 - |X - c|^2 / r^2, 0)^3.
Expr freeform(double cx, const std::vector<Bump>& bumps) {
  Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);
  Expr f = 1.0 - ((X - cx) * (X - cx) + Y * Y + Z * Z);
  for (const Bump& b : bumps) {
    Expr q = 1.0 - ((X - b.c[0]) * (X - b.c[0]) + (Y - b.c[1]) * (Y - b.c[1]) + (Z - b.c[2]) * (Z - b.c[2])) *
                       (1.0 / (b.r * b.r));
    Expr m = max(q, 0.0);
    f = f + b.h * (m * m * m);
  }
  return f;
}

// n bumps on the sphere around (cx, 0, 0), none within 70 degrees of the direction `towards`
// (+1 or -1 along x); `facing` more at the gap, which meet those of the other ball.
std::vector<Bump> bumps(double cx, double towards, int n, int facing, std::mt19937& rng) {
  std::normal_distribution<double> N(0, 1);
  std::vector<Bump> out;
  while (int(out.size()) < n) {
    double d[3] = {N(rng), N(rng), N(rng)};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (double& v : d) v /= len;
    if (d[0] * towards > std::cos(70 * M_PI / 180)) continue;
    out.push_back({{cx + d[0], d[1], d[2]}, 0.25, 0.15});
  }
  // Facing bumps (height 0.15, radius 0.2: each reaches about 0.06 across): one on the axis, or k
  // on a ring of radius 0.15 where the gap is 0.073, overlapping into k contact regions.
  for (int k = 0; k < facing; ++k) {
    const double a = 2 * M_PI * k / std::max(facing, 1), s = facing > 1 ? 0.15 : 0.0;
    const double y = s * std::cos(a), z = s * std::sin(a);
    const double x = cx + towards * std::sqrt(1 - y * y - z * z);
    out.push_back({{x, y, z}, 0.2, 0.15});
  }
  return out;
}

struct Row {
  const char* what;
  int n, contacts;
};

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  const std::vector<int> counts = quick ? std::vector<int>{0, 8, 32} : std::vector<int>{0, 4, 16, 64, 256};
  // Off-centre, so that no early split plane or box centre falls on the gap by accident.
  const Interval box[3] = {{-2.3, 2.7}, {-1.4, 1.6}, {-1.3, 1.7}};
  const double minSize = 1e-3;
  std::printf("two unit balls 0.05 apart, N bumps each away from the gap, k bumps closing it; minSize %g\n", minSize);
  std::printf("%-12s %5s %8s %-12s %12s %10s %10s %10s\n", "case", "N", "contacts", "result", "boxes", "ms",
              "boxes/N=0", "ms/N=0");
  for (int facing : {0, 1, 4, 16}) {
    double baseBoxes = 0, baseMs = 0;
    for (int n : counts) {
      std::mt19937 rng(33 + n);
      TapePtr a = Tape::compile(freeform(-1.025, bumps(-1.025, +1, n, facing, rng)), 3);
      TapePtr b = Tape::compile(freeform(1.025, bumps(1.025, -1, n, facing, rng)), 3);
      const int reps = 3;
      IntersectionResult r;
      const double t0 = bench::cpuSeconds();
      for (int i = 0; i < reps; ++i) r = mayIntersect(*a, *b, box, minSize);
      const double ms = 1e3 * (bench::cpuSeconds() - t0) / reps;
      if (n == counts[0]) baseBoxes = double(r.boxesVisited), baseMs = ms;
      const char* res = r.contact == Contact::Disjoint       ? "disjoint"
                        : r.contact == Contact::Intersecting ? "intersecting"
                                                             : "unknown";
      std::printf("%-12s %5d %8d %-12s %12llu %10.3f %10.2f %10.2f\n", facing ? "colliding" : "disjoint", n, facing,
                  res, (unsigned long long)r.boxesVisited, ms, double(r.boxesVisited) / baseBoxes, ms / baseMs);
    }
  }
  return 0;
}
