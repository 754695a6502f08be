// Volume splines: fit (dense r^3 level, sparse Wendland level), evaluation and bounds.
// The method and its limits are described in frep/primitives/volume_spline.h.
#include "frep/primitives/volume_spline.h"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>

namespace frep {

namespace {

uint64_t mixBits(uint64_t h, double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return h ^ (b + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2));
}

// Wendland's phi_{3,1}(t) = (1 - t)^4 (4t + 1) on [0, 1): C^2, positive definite in 3D.
inline double wendland(double t) {
  if (!(t < 1.0)) return 0.0;
  const double s = 1.0 - t, s2 = s * s;
  return s2 * s2 * (4.0 * t + 1.0);
}

std::string where(size_t i) { return "centre " + std::to_string(i + 1); }

// A uniform grid of cells of size h (at most 128 a side) over the box [lo, lo + cells * h):
// centre indices by cell.
struct CellGrid {
  double lo[3], h;
  int n[3];
  std::vector<uint32_t> start, items;
  int axisCell(double q, int k) const {
    const int c = int(std::floor((q - lo[k]) / h));
    return std::min(std::max(c, 0), n[k] - 1);
  }
  size_t cellOf(const double q[3]) const {
    return (size_t(axisCell(q[2], 2)) * size_t(n[1]) + size_t(axisCell(q[1], 1))) * size_t(n[0]) +
           size_t(axisCell(q[0], 0));
  }
};

CellGrid makeGrid(const std::vector<std::array<double, 3>>& q, const double lo[3], const double hi[3], double h) {
  CellGrid g;
  for (int k = 0; k < 3; ++k) h = std::max(h, (hi[k] - lo[k]) / 128.0);
  g.h = h;
  size_t total = 1;
  for (int k = 0; k < 3; ++k) {
    g.lo[k] = lo[k];
    g.n[k] = std::max(1, int(std::min(128.0, std::ceil((hi[k] - lo[k]) / h))));
    total *= size_t(g.n[k]);
  }
  g.start.assign(total + 1, 0);
  for (const auto& p : q) ++g.start[g.cellOf(p.data()) + 1];
  for (size_t c = 0; c < total; ++c) g.start[c + 1] += g.start[c];
  g.items.resize(q.size());
  std::vector<uint32_t> fill(g.start.begin(), g.start.end() - 1);
  for (size_t i = 0; i < q.size(); ++i) g.items[fill[g.cellOf(q[i].data())]++] = uint32_t(i);
  return g;
}

// Calls fn(j) for every centre in a cell within `reach` of the box [a, b].
template <typename Fn>
void forNear(const CellGrid& g, const double a[3], const double b[3], double reach, Fn&& fn) {
  int lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    const double l = std::floor((a[k] - reach - g.lo[k]) / g.h), u = std::floor((b[k] + reach - g.lo[k]) / g.h);
    if (u < 0.0 || l > g.n[k] - 1) return;
    lo[k] = int(std::max(l, 0.0));
    hi[k] = int(std::min(u, double(g.n[k] - 1)));
  }
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x) {
        const size_t c = (size_t(z) * size_t(g.n[1]) + size_t(y)) * size_t(g.n[0]) + size_t(x);
        for (uint32_t i = g.start[c]; i < g.start[c + 1]; ++i) fn(g.items[i]);
      }
}

double dist2(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

// Range of |q - c| over the box [lo, hi] (exact in real arithmetic; the caller widens the sum).
void distanceRange(const double lo[3], const double hi[3], double cx, double cy, double cz, double& dmin,
                   double& dmax) {
  const double c[3] = {cx, cy, cz};
  double s0 = 0.0, s1 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double below = lo[k] - c[k], above = c[k] - hi[k];
    const double gap = below > 0.0 ? below : (above > 0.0 ? above : 0.0);
    const double far = std::max(c[k] - lo[k], hi[k] - c[k]);
    s0 += gap * gap;
    s1 += far * far;
  }
  dmin = std::sqrt(s0);
  dmax = std::sqrt(s1);
}

}  // namespace

// Fitted splines by the hash of their data, so that compiling a model again in the same process
// (the farm master compiles it for planning and for checking) does not solve again.
namespace {
std::mutex gCacheMutex;
std::multimap<uint64_t, std::weak_ptr<const VolumeSpline>> gCache;
uint64_t dataHash(const std::vector<Point3>& centres, const std::vector<double>& values) {
  uint64_t h = 0x5f1e5eedULL;
  for (size_t i = 0; i < centres.size() && i < values.size(); ++i) {
    for (int k = 0; k < 3; ++k) h = mixBits(h, centres[i][k]);
    h = mixBits(h, values[i]);
  }
  return h;
}
}  // namespace

std::shared_ptr<const VolumeSpline> VolumeSpline::fit(const std::vector<Point3>& centres,
                                                      const std::vector<double>& values) {
  const uint64_t key = dataHash(centres, values);
  {
    std::lock_guard<std::mutex> lock(gCacheMutex);
    for (auto [it, end] = gCache.equal_range(key); it != end;) {
      auto alive = it->second.lock();
      if (!alive) {
        it = gCache.erase(it);
        continue;
      }
      if (alive->centres_ == centres && alive->values_ == values) return alive;
      ++it;
    }
  }
  auto s = solve(centres, values);
  s->hash_ = key;
  std::lock_guard<std::mutex> lock(gCacheMutex);
  gCache.emplace(key, s);
  return s;
}

std::shared_ptr<VolumeSpline> VolumeSpline::solve(const std::vector<Point3>& centres,
                                                  const std::vector<double>& values) {
  const size_t n = centres.size();
  if (values.size() != n)
    throw std::invalid_argument("volume spline: " + std::to_string(n) + " centres but " +
                                std::to_string(values.size()) + " values");
  if (n < 4) throw std::invalid_argument("volume spline: needs at least 4 centres, got " + std::to_string(n));
  if (n > kMaxCentres)
    throw std::invalid_argument("volume spline: " + std::to_string(n) + " centres, more than the limit of " +
                                std::to_string(kMaxCentres));
  auto s = std::shared_ptr<VolumeSpline>(new VolumeSpline());
  s->centres_ = centres;
  s->values_ = values;
  double lo[3], hi[3], vmax = 1.0;
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = centres[0][k];
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(centres[i][k]))
        throw std::invalid_argument("volume spline: " + where(i) + " has a non-finite coordinate");
      lo[k] = std::min(lo[k], centres[i][k]);
      hi[k] = std::max(hi[k], centres[i][k]);
    }
    if (!std::isfinite(values[i])) throw std::invalid_argument("volume spline: " + where(i) + " has a non-finite value");
    vmax = std::max(vmax, std::fabs(values[i]));
  }
  // Normalised coordinates: the bounding box's centre at 0, its largest half-extent 1.
  double half = 0.0;
  for (int k = 0; k < 3; ++k) {
    s->origin_[k] = 0.5 * (lo[k] + hi[k]);
    half = std::max(half, 0.5 * (hi[k] - lo[k]));
  }
  if (!(half > 0.0)) throw std::invalid_argument("volume spline: all centres coincide");
  s->scale_ = half;
  const double inv = 1.0 / half;
  std::vector<std::array<double, 3>> q(n);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) q[i][k] = (centres[i][k] - s->origin_[k]) * inv;

  // Coincident centres make either system singular.
  {
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = uint32_t(i);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return centres[a] < centres[b]; });
    for (size_t i = 1; i < n; ++i)
      if (centres[order[i]] == centres[order[i - 1]])
        throw std::invalid_argument("volume spline: " + where(std::min(order[i], order[i - 1])) + " and " +
                                    where(std::max(order[i], order[i - 1])) + " coincide");
  }

  // Dense level through an evenly strided subset (all centres when n <= kMaxDense).
  const size_t m = std::min(n, kMaxDense);
  std::vector<size_t> sub(m);
  for (size_t k = 0; k < m; ++k) sub[k] = k * n / m;
  Eigen::MatrixXd P(m, 4);
  for (size_t k = 0; k < m; ++k) P.row(Eigen::Index(k)) << 1.0, q[sub[k]][0], q[sub[k]][1], q[sub[k]][2];
  if (Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(P).rank() < 4)
    throw std::invalid_argument("volume spline: the centres lie on one plane (the linear part is undetermined)");
  const Eigen::Index M = Eigen::Index(m) + 4;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(M, M);
  for (size_t i = 0; i < m; ++i)
    for (size_t j = 0; j < m; ++j) {
      const double r = std::sqrt(dist2(q[sub[i]], q[sub[j]]));
      A(Eigen::Index(i), Eigen::Index(j)) = r * r * r;
    }
  A.topRightCorner(Eigen::Index(m), 4) = P;
  A.bottomLeftCorner(4, Eigen::Index(m)) = P.transpose();
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(M);
  for (size_t k = 0; k < m; ++k) rhs(Eigen::Index(k)) = values[sub[k]];
  Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
  Eigen::VectorXd sol = lu.solve(rhs);
  for (int step = 0; step < 2; ++step) sol += lu.solve(rhs - A * sol);  // iterative refinement
  for (size_t k = 0; k < m; ++k) {
    const auto& c = q[sub[k]];
    s->dense_.push_back({c[0], c[1], c[2], sol(Eigen::Index(k))});
  }
  for (int k = 0; k < 4; ++k) s->poly_[k] = sol(Eigen::Index(m) + k);
  A.resize(0, 0);

  if (n > m) {
    // Sparse level: Wendland functions through the dense level's residuals at every centre.
    std::vector<double> resid(n);
    for (size_t i = 0; i < n; ++i) resid[i] = values[i] - s->denseValue(q[i].data());
    double qlo[3], qhi[3], vol = 1.0;
    for (int k = 0; k < 3; ++k) {
      qlo[k] = (lo[k] - s->origin_[k]) * inv;
      qhi[k] = (hi[k] - s->origin_[k]) * inv;
      vol *= std::max(qhi[k] - qlo[k], 1e-3);
    }
    // rho: about 40 neighbours a centre on average (a few rounds of counting).
    double rho = 2.0 * std::cbrt(vol / double(n));
    for (int round = 0; round < 8; ++round) {
      CellGrid g = makeGrid(q, qlo, qhi, rho);
      size_t pairs = 0;
      for (size_t i = 0; i < n && pairs < 400 * n; ++i)
        forNear(g, q[i].data(), q[i].data(), rho, [&](uint32_t j) { pairs += dist2(q[i], q[j]) < rho * rho; });
      const double avg = double(pairs) / double(n);
      if (avg >= 25.0 && avg <= 70.0) break;
      rho *= std::min(2.0, std::max(0.5, std::sqrt(40.0 / std::max(avg, 1.0))));
    }
    CellGrid g = makeGrid(q, qlo, qhi, rho);
    std::vector<Eigen::Triplet<double>> trip;
    for (size_t i = 0; i < n; ++i)
      forNear(g, q[i].data(), q[i].data(), rho, [&](uint32_t j) {
        const double d = std::sqrt(dist2(q[i], q[j]));
        if (d < rho) trip.emplace_back(Eigen::Index(i), Eigen::Index(j), wendland(d / rho));
      });
    const auto nn = static_cast<Eigen::Index>(n);
    Eigen::SparseMatrix<double> W(nn, nn);
    W.setFromTriplets(trip.begin(), trip.end());
    trip.clear();
    trip.shrink_to_fit();
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(W);
    if (ldlt.info() != Eigen::Success)
      throw std::invalid_argument("volume spline: the local (Wendland) system could not be factorised");
    Eigen::Map<const Eigen::VectorXd> b(resid.data(), Eigen::Index(n));
    Eigen::VectorXd mu = ldlt.solve(b);
    mu += ldlt.solve(b - W * mu);
    s->rho_ = rho;
    for (int k = 0; k < 3; ++k) s->gridLo_[k] = g.lo[k], s->cells_[k] = g.n[k];
    s->cellSize_ = g.h;
    s->cellStart_ = g.start;
    for (uint32_t i : g.items) s->sparse_.push_back({q[i][0], q[i][1], q[i][2], mu(Eigen::Index(i))});
  }

  double worst = 0.0;
  for (size_t i = 0; i < n; ++i) worst = std::max(worst, std::fabs(s->value(centres[i].data()) - values[i]));
  s->maxResidual_ = worst;
  if (!(worst <= 1e-9 * vmax))
    throw std::invalid_argument("volume spline: the system is too ill-conditioned (residual " + std::to_string(worst) +
                                " at the centres; are some centres nearly coincident?)");
  return s;
}

std::string VolumeSpline::describe() const {
  return "volume_spline(" + std::to_string(centres_.size()) + " centres)";
}

bool VolumeSpline::sameContent(const FieldFunction& other) const {
  const auto* o = dynamic_cast<const VolumeSpline*>(&other);
  if (!o || o->hash_ != hash_ || o->centres_ != centres_ || o->values_ != values_ || o->dense_.size() != dense_.size() ||
      o->sparse_.size() != sparse_.size())
    return false;
  for (size_t i = 0; i < dense_.size(); ++i)
    if (std::memcmp(&dense_[i], &o->dense_[i], sizeof(Term)) != 0) return false;
  for (size_t i = 0; i < sparse_.size(); ++i)
    if (std::memcmp(&sparse_[i], &o->sparse_[i], sizeof(Term)) != 0) return false;
  return true;
}

double VolumeSpline::denseValue(const double q[3]) const {
  double acc = poly_[0] + poly_[1] * q[0] + poly_[2] * q[1] + poly_[3] * q[2];
  for (const Term& t : dense_) {
    const double dx = q[0] - t.x, dy = q[1] - t.y, dz = q[2] - t.z;
    const double d2 = dx * dx + dy * dy + dz * dz;
    acc += t.w * (d2 * std::sqrt(d2));
  }
  return acc;
}

template <typename Fn>
void VolumeSpline::forSparseNear(const double lo[3], const double hi[3], Fn&& fn) const {
  int a[3], b[3];
  for (int k = 0; k < 3; ++k) {
    const double l = std::floor((lo[k] - rho_ - gridLo_[k]) / cellSize_),
                 u = std::floor((hi[k] + rho_ - gridLo_[k]) / cellSize_);
    if (!(u >= 0.0) || !(l <= cells_[k] - 1)) return;  // also NaN
    a[k] = int(std::max(l, 0.0));
    b[k] = int(std::min(u, double(cells_[k] - 1)));
  }
  for (int z = a[2]; z <= b[2]; ++z)
    for (int y = a[1]; y <= b[1]; ++y)
      for (int x = a[0]; x <= b[0]; ++x) {
        const size_t c = (size_t(z) * size_t(cells_[1]) + size_t(y)) * size_t(cells_[0]) + size_t(x);
        for (uint32_t i = cellStart_[c]; i < cellStart_[c + 1]; ++i) fn(sparse_[i]);
      }
}

double VolumeSpline::sparseValue(const double q[3]) const {
  double acc = 0.0;
  if (sparse_.empty()) return acc;
  forSparseNear(q, q, [&](const Term& t) {
    const double dx = q[0] - t.x, dy = q[1] - t.y, dz = q[2] - t.z;
    acc += t.w * wendland(std::sqrt(dx * dx + dy * dy + dz * dz) / rho_);
  });
  return acc;
}

double VolumeSpline::value(const double p[3]) const {
  const double inv = 1.0 / scale_;
  const double q[3] = {(p[0] - origin_[0]) * inv, (p[1] - origin_[1]) * inv, (p[2] - origin_[2]) * inv};
  const double d = denseValue(q);
  return sparse_.empty() ? d : d + sparseValue(q);
}

void VolumeSpline::values(const double* u, const double* v, const double* w, double* out, size_t n) const {
  thread_local std::vector<double> buf;
  buf.resize(3 * n);
  double *qx = buf.data(), *qy = qx + n, *qz = qy + n;
  const double inv = 1.0 / scale_;
  for (size_t i = 0; i < n; ++i) {
    qx[i] = (u[i] - origin_[0]) * inv, qy[i] = (v[i] - origin_[1]) * inv, qz[i] = (w[i] - origin_[2]) * inv;
    out[i] = poly_[0] + poly_[1] * qx[i] + poly_[2] * qy[i] + poly_[3] * qz[i];
  }
  // Centres outside, points inside: the inner loop vectorises (same operations as denseValue).
  for (const Term& t : dense_) {
    const double cx = t.x, cy = t.y, cz = t.z, wt = t.w;
    for (size_t i = 0; i < n; ++i) {
      const double dx = qx[i] - cx, dy = qy[i] - cy, dz = qz[i] - cz;
      const double d2 = dx * dx + dy * dy + dz * dz;
      out[i] += wt * (d2 * std::sqrt(d2));
    }
  }
  if (sparse_.empty()) return;
  for (size_t i = 0; i < n; ++i) {
    const double q[3] = {qx[i], qy[i], qz[i]};
    out[i] = out[i] + sparseValue(q);
  }
}

double VolumeSpline::gradient(const double p[3], double g[3]) const {
  const double inv = 1.0 / scale_;
  const double q[3] = {(p[0] - origin_[0]) * inv, (p[1] - origin_[1]) * inv, (p[2] - origin_[2]) * inv};
  double gq[3] = {poly_[1], poly_[2], poly_[3]};
  for (const Term& t : dense_) {  // grad |q - c|^3 = 3 |q - c| (q - c)
    const double dx = q[0] - t.x, dy = q[1] - t.y, dz = q[2] - t.z;
    const double k = 3.0 * t.w * std::sqrt(dx * dx + dy * dy + dz * dz);
    gq[0] += k * dx, gq[1] += k * dy, gq[2] += k * dz;
  }
  if (!sparse_.empty()) {
    const double c = -20.0 / (rho_ * rho_);  // grad phi(|d| / rho) = -20 (1 - t)^3 d / rho^2
    forSparseNear(q, q, [&](const Term& t) {
      const double dx = q[0] - t.x, dy = q[1] - t.y, dz = q[2] - t.z;
      const double tt = std::sqrt(dx * dx + dy * dy + dz * dz) / rho_;
      if (!(tt < 1.0)) return;
      const double s = 1.0 - tt, k = c * t.w * s * s * s;
      gq[0] += k * dx, gq[1] += k * dy, gq[2] += k * dz;
    });
  }
  for (int k = 0; k < 3; ++k) g[k] = gq[k] * inv;
  return value(p);
}

namespace {
// Interval a * [lo, hi] for a scalar a, and the product of [a0, a1] with [b0, b1].
inline void mulRange(double a0, double a1, double b0, double b1, double& lo, double& hi) {
  const double p[4] = {a0 * b0, a0 * b1, a1 * b0, a1 * b1};
  lo = std::min(std::min(p[0], p[1]), std::min(p[2], p[3]));
  hi = std::max(std::max(p[0], p[1]), std::max(p[2], p[3]));
}
}  // namespace

Interval VolumeSpline::bound(const Interval box[3]) const {
  // The computed q is monotone in X (rounding is monotone), so the box maps into [q(lo), q(hi)].
  const double inv = 1.0 / scale_;
  double lo[3], hi[3], mid[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = (box[k].lo - origin_[k]) * inv;
    hi[k] = (box[k].hi - origin_[k]) * inv;
    if (!std::isfinite(lo[k]) || !std::isfinite(hi[k])) return Interval::everything();
    mid[k] = 0.5 * (lo[k] + hi[k]);
  }
  // Two enclosures, intersected: the sum of each term's exact range (tight for large boxes),
  // and the mean-value form f(mid) + G . (q - mid) with G the sum of each term's exact gradient
  // range (its overestimate shrinks with the square of the box: the terms' large coefficients
  // cancel in f but not in a sum of ranges). `mag` and `gmag` bound the sums of |terms| for the
  // rounding allowance.
  double sl = poly_[0], sh = poly_[0], mag = std::fabs(poly_[0]);
  double gl[3], gh[3], gmag[3];
  for (int k = 0; k < 3; ++k) {
    const double a = poly_[k + 1] * lo[k], b = poly_[k + 1] * hi[k];
    sl += std::min(a, b), sh += std::max(a, b), mag += std::max(std::fabs(a), std::fabs(b));
    gl[k] = gh[k] = poly_[k + 1], gmag[k] = std::fabs(poly_[k + 1]);
  }
  size_t terms = 4;
  auto addGradient = [&](const Term& t, double f0, double f1) {  // grad = w * [f0, f1] * (q - c)
    const double c[3] = {t.x, t.y, t.z};
    for (int k = 0; k < 3; ++k) {
      double l, h;
      mulRange(f0, f1, lo[k] - c[k], hi[k] - c[k], l, h);
      const double a = t.w * l, b = t.w * h;
      gl[k] += std::min(a, b), gh[k] += std::max(a, b), gmag[k] += std::max(std::fabs(a), std::fabs(b));
    }
  };
  for (const Term& t : dense_) {
    double dmin, dmax;
    distanceRange(lo, hi, t.x, t.y, t.z, dmin, dmax);
    const double a = t.w * (dmin * dmin * dmin), b = t.w * (dmax * dmax * dmax);
    sl += std::min(a, b), sh += std::max(a, b), mag += std::max(std::fabs(a), std::fabs(b));
    addGradient(t, 3.0 * dmin, 3.0 * dmax);  // grad |q - c|^3 = 3 |q - c| (q - c)
  }
  terms += dense_.size();
  if (!sparse_.empty()) {
    const double c = 20.0 / (rho_ * rho_);
    forSparseNear(lo, hi, [&](const Term& t) {
      double dmin, dmax;
      distanceRange(lo, hi, t.x, t.y, t.z, dmin, dmax);
      const double a = t.w * wendland(dmax / rho_), b = t.w * wendland(dmin / rho_);
      sl += std::min(a, b), sh += std::max(a, b), mag += std::fabs(t.w);
      // grad phi = -20 (1 - t)^3 (q - c) / rho^2, (1 - t)^3 decreasing in |q - c|
      const double s0 = std::max(0.0, 1.0 - dmax / rho_), s1 = std::max(0.0, 1.0 - dmin / rho_);
      addGradient(t, -c * s1 * s1 * s1, -c * s0 * s0 * s0);
      ++terms;
    });
  }
  const double u = 2.3e-16 * double(terms + 16);  // per-sum rounding allowance, relative
  double fl = sl - 2.0 * u * mag, fh = sh + 2.0 * u * mag;
  // Mean-value form around the midpoint (evaluated exactly as value() does).
  double qm[3] = {mid[0], mid[1], mid[2]};
  const double fm = denseValue(qm) + (sparse_.empty() ? 0.0 : sparseValue(qm));
  double ml = fm, mh = fm, mmag = 0.0;
  {
    double mm = std::fabs(poly_[0]) + std::fabs(poly_[1] * qm[0]) + std::fabs(poly_[2] * qm[1]) +
                std::fabs(poly_[3] * qm[2]);
    for (const Term& t : dense_) {
      const double dx = qm[0] - t.x, dy = qm[1] - t.y, dz = qm[2] - t.z;
      const double d2 = dx * dx + dy * dy + dz * dz;
      mm += std::fabs(t.w) * d2 * std::sqrt(d2);
    }
    if (!sparse_.empty()) forSparseNear(qm, qm, [&](const Term& t) { mm += std::fabs(t.w); });
    mmag = mm;
  }
  double slackMv = 2.0 * u * mmag;
  for (int k = 0; k < 3; ++k) {
    const double g0 = gl[k] - 2.0 * u * gmag[k], g1 = gh[k] + 2.0 * u * gmag[k];
    // q - mid lies in [lo - mid, hi - mid], widened by an ulp of the coordinates
    const double e = 4.0 * std::numeric_limits<double>::epsilon() * std::max(std::fabs(lo[k]), std::fabs(hi[k]));
    double l, h;
    mulRange(g0, g1, lo[k] - mid[k] - e, hi[k] - mid[k] + e, l, h);
    ml += l, mh += h;
    slackMv += 2.0 * u * std::max(std::fabs(l), std::fabs(h));
  }
  ml -= slackMv + std::numeric_limits<double>::min();
  mh += slackMv + std::numeric_limits<double>::min();
  if (!std::isfinite(fl) || !std::isfinite(fh) || !std::isfinite(ml) || !std::isfinite(mh))
    return Interval::everything();
  return {std::max(fl, ml), std::min(fh, mh)};
}

void offSurfacePoints(const std::vector<Point3>& points, const std::vector<Point3>& normals, double eps,
                      std::vector<Point3>& centres, std::vector<double>& values) {
  if (normals.size() != points.size())
    throw std::invalid_argument("off-surface points: " + std::to_string(points.size()) + " points but " +
                                std::to_string(normals.size()) + " normals");
  if (!(eps > 0.0)) throw std::invalid_argument("off-surface points: the offset must be positive");
  const size_t n = points.size();
  std::vector<Point3> unit(n);
  for (size_t i = 0; i < n; ++i) {
    const auto& nv = normals[i];
    const double len = std::sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
    if (!(len > 0.0) || !std::isfinite(len))
      throw std::invalid_argument("off-surface points: point " + std::to_string(i + 1) + " has a zero normal");
    unit[i] = {nv[0] / len, nv[1] / len, nv[2] / len};
  }
  centres.clear();
  values.clear();
  centres.reserve(3 * n);
  values.reserve(3 * n);
  for (size_t i = 0; i < n; ++i) centres.push_back(points[i]), values.push_back(0.0);
  for (int side = 0; side < 2; ++side) {  // outer (value -eps), then inner (+eps)
    const double sg = side == 0 ? 1.0 : -1.0;
    for (size_t i = 0; i < n; ++i) {
      centres.push_back({points[i][0] + sg * eps * unit[i][0], points[i][1] + sg * eps * unit[i][1],
                         points[i][2] + sg * eps * unit[i][2]});
      values.push_back(-sg * eps);
    }
  }
}

}  // namespace frep
