// Cross-check of the exact volume used by bench_minkowski_peers.py: (cube 10 - ball 6) + ball 1
// = {X : dist(X, A) <= 1}, A = [-5, 5]^3 minus the open ball of radius 6, by the midpoint rule
// over [-6, 6]^3 (one octant, by symmetry) with an exact distance to A, against the
// Steiner-Federer formula V + S + M - 16 pi / 3 derived in the script's header.
// Usage: bench_minkowski_peers_exact [cells per half axis, default 200]   (800: ~1 min)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace {

constexpr double kA = 5.0, kR = 6.0, kPi = 3.141592653589793;

bool inA(const double* p) {
  const double e = 1e-9;
  return std::fabs(p[0]) <= kA + e && std::fabs(p[1]) <= kA + e && std::fabs(p[2]) <= kA + e &&
         p[0] * p[0] + p[1] * p[1] + p[2] * p[2] >= kR * kR * (1 - 1e-12);
}

// The nearest point of A is a critical point of the distance on one stratum of A's boundary:
// a face, edge or corner of the cube (clamping with some coordinates set to +-5), the sphere
// (radial projection) or a circle where the sphere cuts a face. Every candidate that lies in A
// bounds the distance from above, and the nearest point is among them.
double distA(const double* x) {
  if (inA(x)) return 0;
  double best = 1e300, p[3];
  auto cand = [&](const double* q) {
    if (!inA(q)) return;
    double s = 0;
    for (int i = 0; i < 3; ++i) s += (x[i] - q[i]) * (x[i] - q[i]);
    best = std::min(best, s);
  };
  for (int mask = 0; mask < 27; ++mask) {
    int m = mask;
    for (int i = 0; i < 3; ++i, m /= 3) p[i] = m % 3 == 0 ? std::clamp(x[i], -kA, kA) : (m % 3 == 1 ? kA : -kA);
    cand(p);
  }
  const double r = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  if (r > 0) {
    for (int i = 0; i < 3; ++i) p[i] = x[i] * kR / r;
    cand(p);
  }
  const double rho = std::sqrt(kR * kR - kA * kA);
  for (int k = 0; k < 3; ++k)
    for (int s = -1; s <= 1; s += 2) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      const double h = std::hypot(x[i], x[j]);
      p[k] = s * kA;
      p[i] = h > 0 ? rho * x[i] / h : rho;
      p[j] = h > 0 ? rho * x[j] / h : 0;
      cand(p);
    }
  return std::sqrt(best);
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 200;
  const double L = 6.0;  // the sum lies in [-6, 6]^3; its flat faces fall on cell boundaries
  const double h = L / n;
  double count = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const double q[3] = {(i + 0.5) * h, (j + 0.5) * h, (k + 0.5) * h};
        count += distA(q) <= 1.0;
      }
  const double v = 8 * count * h * h * h;
  const double formula = (1000 - 254 * kPi) + (600 + 6 * kPi) +
                         (18 * kPi + 6 * kPi * std::sqrt(11.0) * std::acos(-5.0 / 6)) - 16 * kPi / 3;
  std::printf("%d cells per axis: midpoint volume %.6f, Steiner-Federer %.6f, relative difference %+.2e\n", 2 * n, v,
              formula, (v - formula) / formula);
  return 0;
}
