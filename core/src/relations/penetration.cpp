// Certified penetration depth (issue 33): the shortest translation separating two solids,
// enclosed by proving every nearer translation box colliding (interval arithmetic) and one
// translation separated (mayIntersect, relations.h). The set of colliding translations is the Minkowski
// sum B ⊕ (-A) (Roerdink-Minkowski eq. 1); the depth is its boundary's distance to the origin.
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "frep/evaluators/eval.h"
#include "frep/relations/clearance.h"
#include "frep/relations/relations.h"

namespace frep {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct TBox {
  double lb;  // distance from the origin
  std::vector<Interval> t;
  std::vector<double> hint;  // the point of A that came nearest to proving the parent
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
  const double minT = tol / (2.0 * std::sqrt(double(n)));
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
  auto climb = [&](std::vector<double> p, const std::vector<double>& c, double h, int iters) {
    double f = depthAt(p, c);
    std::vector<double> q(n);
    for (int it = 0; it < iters && h > 1e-9 * reach; ++it) {
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
  // T is proved colliding by a point a of A with fb > 0 on all of a + T. hint: the point the
  // parent box climbed to (children near the boundary start there instead of rescanning).
  auto colliding = [&](const std::vector<Interval>& T, std::vector<double>& hint) {
    for (const std::vector<double>& p : recent)
      if (proves(p, T)) return true;
    std::vector<double> c(n);
    double w = 0.0;
    for (uint32_t i = 0; i < n; ++i) c[i] = T[i].mid(), w = std::max(w, T[i].width());
    // Climbing pays only on boxes small enough for the interval test to pass.
    const bool small = w <= 64.0 * minT;
    // A parent's climbed point is near the optimum already: a short climb from it.
    double h = 4.0 * w;
    int iters = 10;
    if (hint.empty() || !small) {
      h = 1e-2 * reach;
      iters = 40;
      size_t best = 0;
      double bestDepth = -kInf;
      for (size_t k = 0; k < cand.size(); ++k) {
        const double f = depthAt(cand[k], c);
        if (f > bestDepth) bestDepth = f, best = k;
      }
      if (!(bestDepth > 0.0)) return false;  // no sampled point lands in B: leave it to smaller T
      hint = cand[best];
      if (proves(hint, T)) return true;
    }
    if (!small) return false;
    hint = climb(hint, c, h, iters);
    if (!proves(hint, T)) return false;
    recent.insert(recent.begin(), hint);
    if (recent.size() > 8) recent.pop_back();
    return true;
  };
  double lower = kInf;
  // A separated translation in T's direction, proved disjoint by subdivision.
  int attempts = 0;
  auto trySeparate = [&](const std::vector<Interval>& T, double len) -> bool {
    std::vector<double> c(n);
    double cn = 0.0;
    for (uint32_t i = 0; i < n; ++i) c[i] = T[i].mid(), cn += c[i] * c[i];
    cn = std::sqrt(cn);
    if (!(cn > 0.0)) return false;
    if (len >= r.upper) return false;
    ++attempts;
    std::vector<Expr> moved;
    std::vector<Interval> grown(n);
    for (uint32_t i = 0; i < n; ++i) {
      c[i] *= len / cn;
      moved.push_back(Expr::x(i) - c[i]);
      grown[i] = Interval(std::min(box[i].lo, box[i].lo + c[i]), std::max(box[i].hi, box[i].hi + c[i]));
    }
    // One subdivision of space, pruning boxes outside either solid (mayIntersect), proves the
    // thin separation with far fewer boxes than pairs of boxes would.
    TapePtr tm = Tape::compile(remap(a, moved), n);
    const IntersectionResult sep = mayIntersect(*tm, *tb, grown.data(), tol / 8.0);
    if (sep.contact != Contact::Disjoint) return false;
    r.upper = len, r.translation = c;
    return true;
  };

  // Until a nearer one is proved: A moved by the box's narrowest width along its axis leaves
  // the box, so (the solids lying in the box) it is at most touching B.
  r.upper = kInf;
  for (uint32_t i = 0; i < n; ++i)
    if (box[i].width() < r.upper) {
      r.upper = box[i].width();
      r.translation.assign(n, 0.0);
      r.translation[i] = r.upper;
    }
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
    if (r.boxes > opt.maxBoxes || attempts > 24) {
      lower = std::min(lower, T.lb);
      // Out of budget: the nearest box unproved gives the direction; the separation is looked
      // for at doubling distances past the lower bound.
      for (double step = tol; lower + step < r.upper; step *= 2.0)
        if (trySeparate(T.t, lower + step)) break;
      break;
    }
    if (colliding(T.t, T.hint)) continue;
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
    // As far past the lower bound as the tolerance allows: the separation left to prove is then
    // as thick as it can be.
    trySeparate(T.t, lower + 0.9 * tol);
  }
  if (lower == kInf) lower = reach;  // every translation within reach proved colliding
  r.lower = std::min(lower, r.upper);
  r.converged = std::isfinite(r.upper) && r.upper - r.lower <= tol;
  return r;
}

}  // namespace frep
