// Certified penetration depth (issue 33): the shortest translation separating two solids,
// enclosed by proving every nearer translation box colliding (interval arithmetic) and one
// translation separated (clearance.cpp). The set of colliding translations is the Minkowski
// sum B ⊕ (-A) (Roerdink-Minkowski eq. 1); the depth is its boundary's distance to the origin.
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "frep/evaluators/eval.h"
#include "frep/relations/clearance.h"

namespace frep {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct TBox {
  double lb;  // distance from the origin
  std::vector<Interval> t;
  bool operator>(const TBox& o) const { return lb > o.lb; }
};

double originDistance(const std::vector<Interval>& t) {
  double s = 0.0;
  for (const Interval& i : t) {
    const double g = i.lo > 0.0 ? i.lo : i.hi < 0.0 ? -i.hi : 0.0;
    s += g * g;
  }
  return std::sqrt(s);
}

}  // namespace

PenetrationResult penetration(const Expr& a, const Expr& b, uint32_t n, const Interval* box,
                              const PenetrationOptions& opt) {
  PenetrationResult r;
  TapePtr ta = Tape::compile(a, n), tb = Tape::compile(b, n);
  const std::vector<std::vector<double>> cand = samplePoints(*ta, box, size_t(std::max(opt.candidates, 1)));
  if (cand.empty()) return r;  // A has no point in the box: nothing overlaps
  const double tol = opt.tolerance;
  const double minT = tol / (4.0 * std::sqrt(double(n)));
  double reach = 0.0;
  for (uint32_t i = 0; i < n; ++i) reach += box[i].width() * box[i].width();
  reach = std::sqrt(reach);  // a translation this long moves A out of the box

  IntervalEvaluator ie;
  PointEvaluator pe;
  GradientEvaluator ge;
  std::vector<double> x(n), g(n);
  std::vector<Interval> shifted(n);
  std::vector<std::vector<double>> recent;  // points that proved boxes lately, tried first
  auto proves = [&](const std::vector<double>& p, const std::vector<Interval>& T) {
    for (uint32_t i = 0; i < n; ++i) shifted[i] = Interval(p[i] + T[i].lo, p[i] + T[i].hi);
    return ie.eval(*tb, shifted.data()).lo > 0.0;
  };
  auto depthAt = [&](const std::vector<double>& p, const std::vector<double>& c) {
    for (uint32_t i = 0; i < n; ++i) x[i] = p[i] + c[i];
    return pe.eval(*tb, x.data());
  };
  // Moves p over A towards larger fb(p + c) (gradient steps, put back onto A when they leave
  // it): sampled points fall short of A's extreme points, which decide the deep translations.
  auto climb = [&](std::vector<double> p, const std::vector<double>& c) {
    double f = depthAt(p, c), h = 1e-2 * reach;
    std::vector<double> q(n);
    for (int it = 0; it < 40 && h > 1e-9 * reach; ++it) {
      for (uint32_t i = 0; i < n; ++i) x[i] = p[i] + c[i];
      ge.eval(*tb, x.data(), g.data());
      double gn = 0.0;
      for (uint32_t i = 0; i < n; ++i) gn += g[i] * g[i];
      gn = std::sqrt(gn);
      if (!(gn > 0.0) || !std::isfinite(gn)) break;
      for (uint32_t i = 0; i < n; ++i) q[i] = p[i] + h * g[i] / gn;
      const bool onA = pe.eval(*ta, q.data()) >= 0.0 || settleInSolid(*ta, q.data(), box);
      const double fq = onA ? depthAt(q, c) : -kInf;
      if (fq > f) {
        p = q, f = fq, h *= 1.5;
      } else {
        h *= 0.5;
      }
    }
    return p;
  };
  // T is proved colliding by a point a of A with fb > 0 on all of a + T.
  auto colliding = [&](const std::vector<Interval>& T) {
    for (const std::vector<double>& p : recent)
      if (proves(p, T)) return true;
    std::vector<double> c(n);
    for (uint32_t i = 0; i < n; ++i) c[i] = T[i].mid();
    size_t best = 0;
    double bestDepth = -kInf;
    for (size_t k = 0; k < cand.size(); ++k) {
      const double f = depthAt(cand[k], c);
      if (f > bestDepth) bestDepth = f, best = k;
    }
    if (!(bestDepth > 0.0)) return false;  // no sampled point lands in B: leave it to smaller T
    // Climbing pays only on boxes small enough for the interval test to pass.
    double w = 0.0;
    for (const Interval& t : T) w = std::max(w, t.width());
    std::vector<std::vector<double>> tries{cand[best]};
    if (w <= 64.0 * minT) tries.push_back(climb(cand[best], c));
    for (const std::vector<double>& p : tries)
      if (proves(p, T)) {
        recent.insert(recent.begin(), p);
        if (recent.size() > 8) recent.pop_back();
        return true;
      }
    return false;
  };
  double lower = kInf;
  // A separated translation in T's direction, proved by clearance.
  int attempts = 0;
  auto trySeparate = [&](const std::vector<Interval>& T) {
    std::vector<double> c(n);
    double cn = 0.0;
    for (uint32_t i = 0; i < n; ++i) c[i] = T[i].mid(), cn += c[i] * c[i];
    cn = std::sqrt(cn);
    if (!(cn > 0.0)) return;
    // As far as the tolerance allows past the lower bound, in T's direction: the separation
    // left to prove is then as thick as it can be.
    const double len = lower + 0.9 * tol;
    if (!(len > cn)) return;
    if (len >= r.upper) return;
    ++attempts;
    std::vector<Expr> moved;
    std::vector<Interval> grown(n);
    for (uint32_t i = 0; i < n; ++i) {
      c[i] *= len / cn;
      moved.push_back(Expr::x(i) - c[i]);
      grown[i] = Interval(std::min(box[i].lo, box[i].lo + c[i]), std::max(box[i].hi, box[i].hi + c[i]));
    }
    TapePtr tm = Tape::compile(remap(a, moved), n);
    ClearanceOptions co;
    co.tolerance = tol / 4.0;
    co.maxPairs = 200000;
    co.stopWhenSeparated = true;
    ClearanceResult sep = clearance(*tm, *tb, grown.data(), co);
    if (sep.lower > 0.0) r.upper = len, r.translation = c;
  };

  r.upper = kInf;
  std::priority_queue<TBox, std::vector<TBox>, std::greater<TBox>> heap;
  heap.push({0.0, std::vector<Interval>(n, Interval(-reach, reach))});
  while (!heap.empty()) {
    TBox T = heap.top();
    heap.pop();
    ++r.boxes;
    if (T.lb >= r.upper - tol) {
      lower = std::min(lower, T.lb);
      break;
    }
    if (r.boxes > opt.maxBoxes || attempts > 64) {
      lower = std::min(lower, T.lb);
      break;
    }
    if (colliding(T.t)) continue;
    uint32_t axis = 0;
    for (uint32_t i = 1; i < n; ++i)
      if (T.t[i].width() > T.t[axis].width()) axis = i;
    if (T.t[axis].width() > minT) {
      TBox hi = T;
      hi.t[axis].lo = T.t[axis].mid();
      T.t[axis].hi = T.t[axis].mid();
      hi.lb = originDistance(hi.t);
      T.lb = originDistance(T.t);
      heap.push(std::move(hi));
      heap.push(std::move(T));
      continue;
    }
    // The nearest small box not proved colliding is the lower bound; the boxes after it only
    // look for a separation.
    lower = std::min(lower, T.lb);
    trySeparate(T.t);
  }
  if (lower == kInf) lower = reach;  // every translation within reach proved colliding
  r.lower = std::min(lower, r.upper);
  r.converged = std::isfinite(r.upper) && r.upper - r.lower <= tol;
  return r;
}

}  // namespace frep
