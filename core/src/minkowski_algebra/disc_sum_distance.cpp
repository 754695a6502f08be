// Distance to a sum of axis discs by the dual of the projection, and the sum's field
// (disc_sum_distance.h).
#include "frep/minkowski_algebra/disc_sum_distance.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace frep::minkowski {
namespace {

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

// |P_i w|: the length of w's component in the plane of the disc normal to axis i.
double across(const Vec3& w, int i) {
  const int j = (i + 1) % 3, k = (i + 2) % 3;
  return std::hypot(w[j], w[k]);
}

// The relative accuracy the duality gap is driven to (a few ulps).
constexpr double kGap = 8e-16;

}  // namespace

double DiscSum::support(const Vec3& n) const {
  double h = 0;
  for (int i = 0; i < 3; ++i) h += r[i] * across(n, i);
  return h;
}

Vec3 DiscSum::supportPoint(const Vec3& n) const {
  Vec3 y{0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    const double rho = across(n, i);
    if (r[i] == 0 || rho == 0) continue;  // a whole face: its centre will do
    for (int j = 0; j < 3; ++j)
      if (j != i) y[j] += r[i] * n[j] / rho;
  }
  return y;
}

double DiscSum::inradius() const { return std::min({r[1] + r[2], r[0] + r[2], r[0] + r[1]}); }

DiscSum::Distance DiscSum::maximize(const Vec3& q, double t, Vec3 n) const {
  Distance out;
  const double scale = norm(q) + t * (r[0] + r[1] + r[2]);
  // Over a flat face of tD (normal e_i: the disc of radius t r_i at height t Σ_{j≠i} r_j) the
  // maximiser is e_i and the distance the height difference.
  for (int i = 0; i < 3; ++i) {
    const double height = t * (r[0] + r[1] + r[2] - r[i]), rad = t * r[i];
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    if (q[i] >= height * (1 - 4e-16) && q[j] * q[j] + q[k] * q[k] <= rad * rad) {
      out.lo = out.hi = std::max(q[i] - height, 0.0);
      out.n = Vec3{0, 0, 0};
      out.n[i] = 1;
      return out;
    }
  }
  auto value = [&](const Vec3& m) { return dot(m, q) - t * support(m); };
  // The upper bound on an axis direction: the point of that face of tD nearest to q.
  auto facePointDistance = [&](const Vec3& q, double t, const Vec3& m) {
    Vec3 y = supportPoint(m);
    for (int a = 0; a < 3; ++a) {
      if (r[a] == 0 || across(m, a) != 0) continue;
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      const double len = std::hypot(q[b], q[c]), scaleDown = len > t * r[a] ? t * r[a] / len : 1.0;
      y[a] *= t;
      y[b] = y[b] * t + q[b] * scaleDown;
      y[c] = y[c] * t + q[c] * scaleDown;
      return norm(Vec3{q[0] - y[0], q[1] - y[1], q[2] - y[2]});
    }
    return double(INFINITY);
  };
  // Newton in the chart n = cos α e_i + sin α (cos θ e_j + sin θ e_k) around the axis i of n's
  // largest component: h has a cone point at e_i (r_i |n_jk|), which is smooth in (α, θ), so the
  // iteration converges also when the maximiser lies close to the axis (q just off a flat face).
  for (double& c : n) c = std::fabs(c);
  double f = value(n);
  int i = 0, j = 1, k = 2;
  double al = 0, th = 0;
  auto chart = [&]() {
    i = n[0] >= n[1] && n[0] >= n[2] ? 0 : n[1] >= n[2] ? 1 : 2;
    j = (i + 1) % 3;
    k = (i + 2) % 3;
    al = std::acos(std::min(1.0, n[i]));
    th = std::atan2(n[k], n[j]);
  };
  auto point = [&](double a, double b) {
    Vec3 m{0, 0, 0};
    m[i] = std::cos(a);
    m[j] = std::sin(a) * std::cos(b);
    m[k] = std::sin(a) * std::sin(b);
    return m;
  };
  chart();
  for (int it = 0; it < 60; ++it) {
    const Vec3 y = supportPoint(n);
    const Vec3 G{q[0] - t * y[0], q[1] - t * y[1], q[2] - t * y[2]};
    const double hi = std::min(norm(G), facePointDistance(q, t, n));
    out.n = n;
    out.lo = f;
    out.hi = hi;
    if (hi - f <= kGap * scale) break;
    // At the axis θ is free and g's slope in α is q_jk·(cos θ, sin θ) − t r_i: face q_jk.
    if (al < 1e-7) th = std::atan2(q[k], q[j]);
    const double ca = std::cos(al), sa = std::sin(al), ct = std::cos(th), st = std::sin(th);
    Vec3 na{0, 0, 0}, nt{0, 0, 0}, nat{0, 0, 0}, ntt{0, 0, 0};
    na[i] = -sa, na[j] = ca * ct, na[k] = ca * st;
    nt[j] = -sa * st, nt[k] = sa * ct;
    nat[j] = -ca * st, nat[k] = ca * ct;
    ntt[j] = -sa * ct, ntt[k] = -sa * st;
    // Quadratic forms of ∇²h = Σ_m r_m (P_m − u_m u_mᵀ) / |P_m n|: the chart axis's disc adds
    // r_i sin α to the θθ entry only; the others have |P_m n| >= n_i >= 1/√3.
    double haa = 0, hat = 0, htt = r[i] * sa;
    for (int m = 0; m < 3; ++m) {
      if (m == i || r[m] == 0) continue;
      const double rho = across(n, m);
      Vec3 u = n;
      u[m] = 0;
      for (double& c : u) c /= rho;
      auto form = [&](const Vec3& v, const Vec3& w) {
        const double pv = dot(v, w) - v[m] * w[m];
        return r[m] * (pv - dot(u, v) * dot(u, w)) / rho;
      };
      haa += form(na, na);
      hat += form(na, nt);
      htt += form(nt, nt);
    }
    const double ga = dot(G, na), gt = dot(G, nt);
    // The Hessian of g(α, θ) = n·q − t h(n): −t ∇²h forms + G·(second derivatives of n).
    const double Haa = -t * haa - dot(G, n), Hat = -t * hat + dot(G, nat), Htt = -t * htt + dot(G, ntt);
    double da, dt;
    const double det = Haa * Htt - Hat * Hat;
    if (Haa < 0 && det > 0) {
      da = -(Htt * ga - Hat * gt) / det;
      dt = -(Haa * gt - Hat * ga) / det;
    } else {  // indefinite (θ far from its best near the axis): Newton per coordinate
      da = Haa < 0 ? -ga / Haa : ga;
      dt = Htt < 0 ? -gt / Htt : gt;
    }
    const double slope = da * ga + dt * gt;
    bool moved = false;
    double step = 1;
    for (int s = 0; s < 60 && slope > 0; ++s, step *= 0.5) {
      double a2 = al + step * da, t2 = th + step * dt;
      if (a2 < 0) a2 = -a2, t2 += M_PI;
      const Vec3 m = point(a2, t2);
      const double fm = value(m);
      if (fm >= f + 1e-4 * step * slope && m != n) {
        n = m;
        f = fm;
        al = a2;
        th = t2;
        moved = true;
        break;
      }
    }
    if (!moved) break;
    // Back to n >= 0 (as good: q >= 0 and h is even in each component) and a fresh chart.
    for (double& c : n) c = std::fabs(c);
    f = value(n);
    chart();
  }
  if (value(n) > out.lo) {  // the last step's direction, if better
    out.n = n;
    out.lo = value(n);
    const Vec3 y = supportPoint(n);
    out.hi = std::min(out.hi, norm(Vec3{q[0] - t * y[0], q[1] - t * y[1], q[2] - t * y[2]}));
  }
  out.hi = std::max(out.hi, out.lo);
  return out;
}

DiscSum::Distance DiscSum::distance(const Vec3& qIn) const {
  const Vec3 q{std::fabs(qIn[0]), std::fabs(qIn[1]), std::fabs(qIn[2])};
  Distance out;
  const double qn = norm(q);
  if (qn == 0) {
    out.inside = true;
    return out;
  }
  // Dinkelbach's iteration for the gauge γ = max n·q / h(n) from below: t <= γ, so q lies
  // outside tD and the ascent from the last direction starts where n·q − t h(n) >= 0. Once
  // t > 1 (q is outside D) the same ascent at t = 1 gives the distance.
  const double rin = inradius();
  Vec3 n{q[0] / qn, q[1] / qn, q[2] / qn};
  double t = qn / support(n);
  for (int k = 0; k < 60; ++k) {
    const double tt = std::min(t, 1.0);
    const Distance m = maximize(q, tt, n);
    n = m.n;
    if (tt == 1.0) {
      out = m;
      return out;
    }
    out.gaugeHi = tt + m.hi / rin;
    const double next = dot(n, q) / support(n);
    if (next > 1) {
      t = next;
      continue;
    }
    if (out.gaugeHi - next <= kGap * out.gaugeHi || next <= t) {
      out.inside = true;
      out.n = n;
      out.gaugeLo = std::max(t, next);
      out.gaugeHi = std::max(out.gaugeHi, out.gaugeLo);
      return out;
    }
    t = next;
  }
  out.inside = true;
  out.n = n;
  out.gaugeLo = std::min(t, 1.0);
  out.gaugeHi = std::max(out.gaugeHi, out.gaugeLo);
  return out;
}

double DiscSum::signedDistance(const Vec3& q, double s, double* error) const {
  const double scale = norm(q) + r[0] + r[1] + r[2] + s;
  const Distance d = distance(q);
  if (!d.inside) {
    // lo is n·q − h(n): off by O(|n − n*|²), so exact to rounding once n has converged; hi (the
    // support point's distance) is off by O(|n − n*|² / dist) and only certifies the error.
    *error = (d.hi - d.lo) + kGap * scale;
    return d.lo - s;
  }
  // Inside D: r (1 − γ); a bracket of γ above 1 means q may lie outside D by up to
  // (γ − 1) max h, which r (1 − γ) then misses by at most that much.
  const double rin = inradius(), gamma = d.gaugeLo;
  double err = rin * (d.gaugeHi - d.gaugeLo) + kGap * scale;
  if (d.gaugeHi > 1) err += (d.gaugeHi - 1) * (r[0] + r[1] + r[2]);
  *error = err;
  return -s - rin * (1 - gamma);
}

DiscSumField::DiscSumField(const Vec3& lengths, const Vec3& radii, double ball)
    : lengths_(lengths), ball_(ball) {
  discs_.r = radii;
}

std::string DiscSumField::describe() const {
  char b[200];
  std::snprintf(b, sizeof b, "disc_sum(block %g x %g x %g, discs %g %g %g, ball %g)", lengths_[0], lengths_[1],
                lengths_[2], discs_.r[0], discs_.r[1], discs_.r[2], ball_);
  return b;
}

uint64_t DiscSumField::contentHash() const {
  uint64_t h = 0x9e3779b97f4a7c15ull;
  const double v[7] = {lengths_[0], lengths_[1], lengths_[2], discs_.r[0], discs_.r[1], discs_.r[2], ball_};
  for (double x : v) {
    uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    h = (h ^ bits) * 0x100000001b3ull;
    h ^= h >> 29;
  }
  return h;
}

bool DiscSumField::sameGeometry(const DistanceField& other) const {
  const auto& o = static_cast<const DiscSumField&>(other);
  return o.lengths_ == lengths_ && o.discs_.r == discs_.r && o.ball_ == ball_;
}

double DiscSumField::valueWithError(const double p[3], double* error) const {
  Vec3 e;
  for (int i = 0; i < 3; ++i) e[i] = std::max(std::fabs(p[i] - 0.5 * lengths_[i]) - 0.5 * lengths_[i], 0.0);
  return -discs_.signedDistance(e, ball_, error);
}

double DiscSumField::value(const double p[3]) const {
  double err;
  return valueWithError(p, &err);
}

Interval DiscSumField::bound(const Interval box[3]) const {
  double c[3], r2 = 0;
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(box[i].lo) || !std::isfinite(box[i].hi)) return Interval::everything();
    c[i] = 0.5 * (box[i].lo + box[i].hi);
    const double h = std::max(box[i].hi - c[i], c[i] - box[i].lo);
    r2 += h * h;
  }
  double err;
  const double v = valueWithError(c, &err);
  if (std::isnan(v)) return Interval::everything();
  // 1-Lipschitz: |f(p) − f(c)| <= |p − c|; the value's certified error and rounding on top.
  const double r = std::sqrt(r2) * (1 + 1e-12);
  const double slack = err + 1e-12 * (std::fabs(v) + r) + std::numeric_limits<double>::denorm_min();
  return {v - r - slack, v + r + slack};
}

}  // namespace frep::minkowski
