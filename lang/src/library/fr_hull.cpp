// frHull(x, A [, n]): an outer polytope of the convex hull of object A (3D), from A's support
// function h(u) = max over A of u·p in 6 n² directions (the centres of an n x n grid on each
// face of the cube, normalised; n defaults to 9, 486 planes: odd n includes the axes, so a box's
// hull is the box). h is bounded above by interval
// subdivision of A's box (every box not proved outside A, down to 1/256 of the box's extent), so
// the polytope min_k (h_k − u_k·X) contains conv(A) (Roerdink-Minkowski §II: a convex set is
// the intersection of its supporting half-spaces). How far it reaches past conv(A): a point at
// distance d from conv(A) has d ≤ (e + 4 R sin(θ/2)) / cos θ, θ = atan(√2 / n) the directions'
// covering angle, e the support's overestimate (one leaf box's diagonal), R the radius of a
// ball around A (docs/language.md).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/evaluators/interval.h"
#include "frep/expressions/tape.h"
#include "frep/lang/library/library.h"

namespace frep::lang {
namespace {

using Box = std::array<Interval, 3>;

// Boxes covering {f >= 0} within [-1000, 1000]^3: the ones not proved outside, split down to
// 1/256 of the hull of the ones kept (boxes proved inside are kept whole).
std::vector<Box> cover(const Expr& f, const std::string& name) {
  TapePtr tape = Tape::compile(f, 3);
  IntervalEvaluator ev;
  std::vector<Box> done, amb{Box{Interval(-1000, 1000), Interval(-1000, 1000), Interval(-1000, 1000)}};
  for (int level = 0; level < 40 && !amb.empty(); ++level) {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (const std::vector<Box>* v : {&done, &amb})
      for (const Box& b : *v)
        for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], b[d].lo), hi[d] = std::max(hi[d], b[d].hi);
    double extent = 0;
    for (int d = 0; d < 3; ++d) extent = std::max(extent, hi[d] - lo[d]);
    if (amb[0][0].width() <= extent / 256.0) break;
    if (amb.size() > 300000)
      throw LibraryError("frHull: object '" + name + "' needs more than 300000 boxes to bound; give it a simpler field",
                         1);
    std::vector<Box> next;
    for (const Box& b : amb)
      for (int c = 0; c < 8; ++c) {
        Box k;
        for (int d = 0; d < 3; ++d)
          k[size_t(d)] = (c >> d) & 1 ? Interval(b[size_t(d)].mid(), b[size_t(d)].hi)
                                      : Interval(b[size_t(d)].lo, b[size_t(d)].mid());
        const Interval v = ev.eval(*tape, k.data());
        if (v.hi < 0.0) continue;
        (v.lo >= 0.0 ? done : next).push_back(k);
      }
    amb = std::move(next);
  }
  done.insert(done.end(), amb.begin(), amb.end());
  if (done.empty()) throw LibraryError("frHull: object '" + name + "' is empty within ±1000 (no point with f >= 0)", 1);
  for (const Box& b : done)
    for (const Interval& i : b)
      if (i.lo <= -1000 || i.hi >= 1000)
        throw LibraryError("frHull: object '" + name + "' is not bounded within ±1000", 1);
  return done;
}

Expr frHull(std::vector<Arg>& a) {
  const char* fn = "frHull";
  if (a.size() != 2 && a.size() != 3) throw LibraryError("frHull takes (x, A [, n])");
  if (!a[0].isArray || !a[0].array || a[0].array->size() < 3)
    throw LibraryError("frHull: argument 1 must be the coordinate array (x) of 3 or more", 0);
  if (!a[1].isObject || a[1].objectDims != 3)
    throw LibraryError("frHull: argument 2 (A) must be the name of a 3D object defined earlier in the file", 1);
  if (numParams(a[1].value) > 0)
    throw LibraryError("frHull: object '" + a[1].name + "' reads a[] values that are not known at compile time", 1);
  int n = 9;
  if (a.size() == 3) {
    if (a[2].isArray || a[2].isObject || !a[2].value.isConst())
      throw LibraryError("frHull: n (argument 3) must be a constant", 2);
    const double v = a[2].value.constValue();
    if (!(v == std::floor(v) && v >= 1 && v <= 64))
      throw LibraryError("frHull: n must be a whole number from 1 to 64", 2);
    n = int(v);
  }
  const std::vector<Box> boxes = cover(a[1].value, a[1].name);
  // The boxes in chunks of 64 and the chunks in groups of 64 (the cover lists siblings together,
  // so both are compact), each with its bounding box: a group or chunk whose bounding box's
  // support is at most the best value found is skipped. Its boxes' values cannot exceed it (the
  // same sums of larger terms, and rounding is monotone), so h is the same as scanning every
  // box, for a fraction of the work.
  constexpr size_t kChunk = 64;
  auto boundsOf = [](const std::vector<Box>& items) {
    std::vector<Box> out;
    for (size_t c = 0; c < items.size(); c += kChunk) {
      Box b = items[c];
      for (size_t k = c + 1; k < std::min(items.size(), c + kChunk); ++k)
        for (size_t d = 0; d < 3; ++d)
          b[d] = Interval(std::min(b[d].lo, items[k][d].lo), std::max(b[d].hi, items[k][d].hi));
      out.push_back(b);
    }
    return out;
  };
  const std::vector<Box> chunks = boundsOf(boxes), groups = boundsOf(chunks);
  auto supportOf = [](const Box& b, const double* u) {
    double v = 0;
    for (int d = 0; d < 3; ++d) v += u[d] * (u[d] >= 0 ? b[size_t(d)].hi : b[size_t(d)].lo);
    return v;
  };
  const std::vector<Expr>& xs = *a[0].array;
  Expr result;
  bool first = true;
  for (int face = 0; face < 6; ++face)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        // Cell centre (s, t) on face `face` of the cube [-1, 1]^3.
        const double s = -1 + (2 * i + 1.0) / n, t = -1 + (2 * j + 1.0) / n, w = face % 2 ? 1.0 : -1.0;
        double u[3];
        const int ax = face / 2;
        u[ax] = w;
        u[(ax + 1) % 3] = s;
        u[(ax + 2) % 3] = t;
        const double norm = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        for (double& c : u) c /= norm;
        // Upper bound of the support: the largest u·p over the corners of the covering boxes.
        double h = -1e300;
        for (size_t g = 0; g < groups.size(); ++g)  // values reached: the first skip threshold
          h = std::max(h, supportOf(boxes[g * kChunk * kChunk], u));
        for (size_t g = 0; g < groups.size(); ++g) {
          if (!(supportOf(groups[g], u) > h)) continue;
          for (size_t c = g * kChunk; c < std::min(chunks.size(), (g + 1) * kChunk); ++c) {
            if (!(supportOf(chunks[c], u) > h)) continue;
            for (size_t k = c * kChunk; k < std::min(boxes.size(), (c + 1) * kChunk); ++k)
              h = std::max(h, supportOf(boxes[k], u));
          }
        }
        Expr plane = Expr(h) - (u[0] * xs[0] + u[1] * xs[1] + u[2] * xs[2]);
        result = first ? plane : min(result, plane);
        first = false;
      }
  return result;
}

const bool registered = registerAll({
    {"frHull", "*", "outer polytope of the convex hull of object A: 6 n^2 supporting planes (n = 9 by default)",
     frHull},
});

}  // namespace
}  // namespace frep::lang
