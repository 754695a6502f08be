// Certified clearance of two solids by branch and bound over pairs of boxes (issue 33; the
// box tests of Vyatkin-Perturbation's collision detection, with a distance instead of a yes/no).
#include "frep/relations/clearance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <queue>

#include "frep/evaluators/eval.h"
#include "frep/relations/relations.h"

namespace frep {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool inBox(const double* x, const Interval* box, uint32_t n) {
  for (uint32_t i = 0; i < n; ++i)
    if (!(x[i] >= box[i].lo && x[i] <= box[i].hi)) return false;
  return true;
}

double distance(const std::vector<double>& p, const std::vector<double>& q) {
  double s = 0.0;
  for (size_t i = 0; i < p.size(); ++i) s += (p[i] - q[i]) * (p[i] - q[i]);
  return std::sqrt(s);
}

// Distance between two boxes: a lower bound of the distance of any of their points.
double boxDistance(const std::vector<Interval>& a, const std::vector<Interval>& b) {
  double s = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double g = std::max({0.0, b[i].lo - a[i].hi, a[i].lo - b[i].hi});
    s += g * g;
  }
  return std::sqrt(s);
}

double maxWidth(const std::vector<Interval>& b) {
  double w = 0.0;
  for (const Interval& i : b) w = std::max(w, i.width());
  return w;
}

// The boxes of one solid, split on demand along any axis; a child certified outside the solid
// (f < 0 on it) is never made. Each box also keeps one point of the solid, when one is found.
class SolidBoxes {
 public:
  SolidBoxes(const Tape& tape, uint32_t n, const Interval* box) : tape_(tape), n_(n), global_(box, box + n) {
    if (ie_.eval(tape_, global_.data()).hi >= 0.0) add(global_);
  }
  bool empty() const { return nodes_.empty(); }
  const std::vector<Interval>& box(int id) const { return nodes_[size_t(id)].box; }

  // Children of box id split at the middle of axis (-1: outside the solid).
  std::array<int, 2> children(int id, uint32_t axis) {
    std::array<int, 2> k = nodes_[size_t(id)].kids[axis];
    if (k[0] != -2) return k;
    for (int side = 0; side < 2; ++side) {
      std::vector<Interval> b = nodes_[size_t(id)].box;
      const double mid = b[axis].mid();
      (side ? b[axis].lo : b[axis].hi) = mid;
      k[size_t(side)] = ie_.eval(tape_, b.data()).hi < 0.0 ? -1 : add(b);
    }
    nodes_[size_t(id)].kids[axis] = k;
    return k;
  }

  // A point of the solid for box id (its centre, or the centre settled onto the surface).
  const std::vector<double>* point(int id) {
    Node& nd = nodes_[size_t(id)];
    if (nd.pointState == 0) {
      nd.point.resize(n_);
      for (uint32_t i = 0; i < n_; ++i) nd.point[i] = nd.box[i].mid();
      const bool ok = pe_.eval(tape_, nd.point.data()) >= 0.0 || settleInSolid(tape_, nd.point.data(), global_.data());
      nd.pointState = ok ? 1 : -1;
    }
    return nd.pointState == 1 ? &nd.point : nullptr;
  }

  // p moved onto this solid (Newton from p): a nearby point of it, when found.
  bool settle(std::vector<double>& p) { return settleInSolid(tape_, p.data(), global_.data()); }

 private:
  struct Node {
    std::vector<Interval> box;
    std::vector<std::array<int, 2>> kids;  // per axis; -2: not split yet
    int pointState = 0;                    // 0 untried, 1 found, -1 none
    std::vector<double> point;
  };
  int add(const std::vector<Interval>& b) {
    nodes_.push_back(Node{b, std::vector<std::array<int, 2>>(n_, {-2, -2}), 0, {}});
    return static_cast<int>(nodes_.size() - 1);
  }
  const Tape& tape_;
  uint32_t n_;
  std::vector<Interval> global_;
  std::vector<Node> nodes_;
  IntervalEvaluator ie_;
  PointEvaluator pe_;
};

struct Pair {
  double lb;
  int a, b;
  bool operator>(const Pair& o) const {
    if (lb != o.lb) return lb > o.lb;
    return a != o.a ? a > o.a : b > o.b;  // deterministic order among equal bounds
  }
};

}  // namespace

bool settleInSolid(const Tape& tape, double* x, const Interval* box) {
  const uint32_t n = tape.numVars();
  double f = projectToSurface(tape, x, 30, 0.0);
  if (!std::isfinite(f)) return false;
  if (f < 0.0) {
    // Rounding left x just outside: step inward along the gradient, doubling the step.
    GradientEvaluator ge;
    std::vector<double> g(std::max<uint32_t>(n, 1)), y(x, x + n);
    ge.eval(tape, x, g.data());
    double g2 = 0.0, scale = 1.0;
    for (uint32_t i = 0; i < n; ++i) g2 += g[i] * g[i], scale = std::max(scale, std::fabs(x[i]));
    if (!(g2 > 0.0) || !std::isfinite(g2)) return false;
    const double gn = std::sqrt(g2);
    PointEvaluator pe;
    bool ok = false;
    for (double s = 1e-14 * scale; s < 1e-6 * scale && !ok; s *= 2.0) {
      for (uint32_t i = 0; i < n; ++i) y[i] = x[i] + s * g[i] / gn;
      ok = pe.eval(tape, y.data()) >= 0.0;
    }
    if (!ok) return false;
    std::copy(y.begin(), y.end(), x);
  }
  return inBox(x, box, n);
}

ClearanceResult clearance(const Tape& ta, const Tape& tb, const Interval* box, const ClearanceOptions& opt) {
  const uint32_t n = std::max({ta.numVars(), tb.numVars(), 1u});
  ClearanceResult r;
  SolidBoxes A(ta, n, box), B(tb, n, box);
  r.emptyA = A.empty();
  r.emptyB = B.empty();
  if (r.emptyA || r.emptyB) {
    r.lower = r.upper = kInf;
    return r;
  }
  const double tol = opt.tolerance;
  const double minSize = opt.minSize > 0.0 ? opt.minSize : tol / 16.0;
  double upper = kInf;
  auto offer = [&](const std::vector<double>& p, const std::vector<double>& q) {
    const double d = distance(p, q);
    if (d < upper) upper = d, r.a = p, r.b = q;
  };
  // Upper bound from a pair: the boxes' points, then one round of alternating projections
  // (each point moved onto the other solid from its partner), which finds the nearest points of
  // two balls and of parallel faces at once.
  auto tryPair = [&](int ia, int ib) {
    const std::vector<double>*pa = A.point(ia), *pb = B.point(ib);
    if (!pa || !pb) return;
    offer(*pa, *pb);
    std::vector<double> qa = *pb;
    if (!A.settle(qa)) return;
    offer(qa, *pb);
    std::vector<double> qb = qa;
    if (B.settle(qb)) offer(qa, qb);
  };

  std::priority_queue<Pair, std::vector<Pair>, std::greater<Pair>> heap;
  heap.push({0.0, 0, 0});
  double lower = kInf;
  bool stuck = false;
  while (!heap.empty()) {
    const Pair p = heap.top();
    if (r.pairs >= opt.maxPairs) {
      lower = p.lb;
      stuck = true;
      break;
    }
    heap.pop();
    ++r.pairs;
    if (p.lb >= upper - tol) {
      lower = p.lb;
      break;
    }
    const std::vector<Interval>&ba = A.box(p.a), &bb = B.box(p.b);
    const double wa = maxWidth(ba), wb = maxWidth(bb);
    tryPair(p.a, p.b);
    if (p.lb >= upper - tol) {
      lower = p.lb;
      break;
    }
    if (std::max(wa, wb) <= minSize) {  // cannot refine the nearest pair further
      lower = p.lb;
      stuck = true;
      break;
    }
    // Split the larger box, along the axis that is long and points at the other box: parallel
    // faces then separate in slabs instead of in cubes (fewer pairs at the same distance).
    const bool splitA = wa >= wb;
    const std::vector<Interval>& s = splitA ? ba : bb;
    // The direction is the gap between the boxes (their centres' offset while they overlap):
    // splitting across it is what raises the pair's bound.
    std::vector<double> u(n);
    double un = 0.0;
    for (uint32_t i = 0; i < n; ++i) {
      u[i] = p.lb > 0.0 ? std::max({0.0, bb[i].lo - ba[i].hi, ba[i].lo - bb[i].hi}) : bb[i].mid() - ba[i].mid();
      un += u[i] * u[i];
    }
    un = std::sqrt(un);
    uint32_t axis = 0;
    double best = -1.0;
    for (uint32_t i = 0; i < n; ++i) {
      const double score = s[i].width() * (0.05 + (un > 0.0 ? std::fabs(u[i]) / un : 0.0));
      if (score > best) best = score, axis = i;
    }
    const std::array<int, 2> kids = (splitA ? A : B).children(splitA ? p.a : p.b, axis);
    for (int k : kids) {
      if (k < 0) continue;
      const int ia = splitA ? k : p.a, ib = splitA ? p.b : k;
      const double lb = boxDistance(A.box(ia), B.box(ib));
      if (lb <= upper) heap.push({lb, ia, ib});
    }
  }
  if (heap.empty() && lower == kInf) lower = upper;  // every pair was farther than the witnesses
  r.lower = std::min(lower, upper);
  r.upper = upper;
  r.converged = std::isfinite(upper) && !stuck && r.upper - r.lower <= tol;
  return r;
}

std::vector<std::vector<double>> samplePoints(const Tape& tape, const Interval* box, size_t maxPoints) {
  const uint32_t n = std::max(tape.numVars(), 1u);
  IntervalEvaluator ie;
  PointEvaluator pe;
  struct Cell {
    std::vector<Interval> b;
    bool inside;
  };
  std::vector<Cell> cells;
  {
    std::vector<Interval> root(box, box + n);
    const Interval v = ie.eval(tape, root.data());
    if (v.hi < 0.0) return {};
    cells.push_back({root, v.lo >= 0.0});
  }
  const size_t kids = size_t{1} << n;
  while (cells.size() * kids <= maxPoints) {
    std::vector<Cell> next;
    for (const Cell& c : cells) {
      for (size_t k = 0; k < kids; ++k) {
        std::vector<Interval> b = c.b;
        for (uint32_t d = 0; d < n; ++d) ((k >> d) & 1 ? b[d].lo : b[d].hi) = c.b[d].mid();
        if (c.inside) {
          next.push_back({b, true});
          continue;
        }
        const Interval v = ie.eval(tape, b.data());
        if (v.hi >= 0.0) next.push_back({b, v.lo >= 0.0});
      }
    }
    if (next.empty()) break;
    cells = std::move(next);
  }
  std::vector<std::vector<double>> pts;
  for (const Cell& c : cells) {
    std::vector<double> p(n);
    for (uint32_t d = 0; d < n; ++d) p[d] = c.b[d].mid();
    if (pe.eval(tape, p.data()) >= 0.0) {
      pts.push_back(p);
      // A boundary cell also gives its point on the surface: the extreme points of the solid
      // are on it, and they are the ones that prove deep overlaps.
      if (!c.inside && settleInSolid(tape, p.data(), box)) pts.push_back(p);
    } else if (settleInSolid(tape, p.data(), box)) {
      pts.push_back(p);
    }
  }
  return pts;
}

}  // namespace frep
