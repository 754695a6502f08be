// frepfarm's fr* extremum extensions (issue 6, docs/extremum.md "The language side"): Minkowski
// sum and difference, projection, sweep, constant-radius offset and Minkowski metamorphosis of
// OBJECTS defined earlier in the file. Each lowers to one extremum node (frep/extremum/extremum.h) over
// the callee's compiled field, read through the caller's coordinate array. Sweeps also take
// keyframe motions (frSweepKeys; frKeyframe is the interpolant alone, for motion objects).
//
// Options: an optional trailing array [method, tol, lo1, hi1, ..., lok, hik]: method 0 =
// branch-and-bound (default), 1 = the paper's grid; tol = the B&B certified gap or the grid step
// (0 = default); then the searched operand's box (pairs per coordinate) when the automatic one
// is not wanted. Every option must be a constant known at compile time.
//
// Automatic boxes: interval subdivision of [-1000, 1000]^n on the operand's field, keeping the
// boxes not certified outside (hull of the rest is a sound enclosure of the solid).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "frep/evaluators/eval.h"
#include "frep/extremum/extremum.h"
#include "frep/evaluators/interval.h"
#include "frep/expressions/tape.h"
#include "frep/minkowski_algebra/distance_offset.h"
#include "frep/minkowski_algebra/path_sweep.h"
#include "frep/minkowski_algebra/mesh_convex_sum.h"
#include "frep/minkowski_algebra/sampled_operand.h"
#include "frep/relations/relations.h"
#include "library/fr_minkowski.h"
#include "library/hf_util.h"

namespace frep::lang {
namespace {

using hf::constArg;
using hf::guarded;

constexpr double kSearchLimit = 1000.0;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

const Arg& objectArg(const char* fn, std::vector<Arg>& a, int i, const char* role) {
  if (i >= static_cast<int>(a.size()) || !a[i].isObject)
    throw LibraryError(std::string(fn) + ": argument " + std::to_string(i + 1) + " (" + role +
                           ") must be the name of an object defined earlier in the file",
                       i);
  if (numParams(a[i].value) > 0)
    throw LibraryError(std::string(fn) + ": object '" + a[i].name +
                           "' reads a[] values that are not known at compile time here; " +
                           "call it from an object without a[] or bind them in an object of its own",
                       i);
  return a[i];
}

std::vector<Expr>& coordArg(const char* fn, std::vector<Arg>& a, size_t n) {
  if (a.empty() || !a[0].isArray || !a[0].array)
    throw LibraryError(std::string(fn) + ": argument 1 must be the coordinate array (x)", 0);
  if (a[0].array->size() < n)
    throw LibraryError(std::string(fn) + ": the result has " + std::to_string(n) +
                           " coordinates but array '" + a[0].name + "' has only " +
                           std::to_string(a[0].array->size()),
                       0);
  return *a[0].array;
}

// Reads the result (over x[0..n)) through the caller's coordinates.
Expr through(const Expr& result, const std::vector<Expr>& xs, size_t n) {
  return remap(result, std::vector<Expr>(xs.begin(), xs.begin() + static_cast<long>(n)));
}

struct Options {
  SearchOptions search;
  bool hasBox = false;
  Bounds box;
  int sampleRes = 0;  // method 2: the sampled operand's grid (0: search)
};

// The trailing options array (argument i, when present); boxDims: coordinates of the box.
Options parseOptions(const char* fn, std::vector<Arg>& a, int i, size_t boxDims) {
  Options o;
  if (i >= static_cast<int>(a.size())) return o;
  if (!a[i].isArray || !a[i].array)
    throw LibraryError(std::string(fn) + ": the options must be an array [method, tol, lo1, hi1, ...]",
                       i);
  const std::vector<Expr>& v = *a[i].array;
  for (size_t k = 0; k < v.size(); ++k)
    if (!v[k].isConst())
      throw LibraryError(std::string(fn) + ": option " + a[i].name + "[" + std::to_string(k + 1) +
                             "] must be a constant known at compile time",
                         i);
  if (v.size() != 2 && v.size() != 2 + 2 * boxDims)
    throw LibraryError(std::string(fn) + ": the options array must have 2 elements [method, tol] " +
                           "or " + std::to_string(2 + 2 * boxDims) +
                           " [method, tol, lo1, hi1, ...] (got " + std::to_string(v.size()) + ")",
                       i);
  double method = v[0].constValue(), tol = v[1].constValue();
  const bool sampling = std::string(fn) == "frMinkowski" || std::string(fn) == "frMinkowskiDiff";
  if (method != 0.0 && method != 1.0 && !(method == 2.0 && sampling))
    throw LibraryError(std::string(fn) + ": method (options[1]) must be 0 (branch-and-bound), 1 (grid) or 2 "
                                         "(sampled operand: frMinkowski, frMinkowskiDiff)",
                       i);
  if (!(tol >= 0.0))
    throw LibraryError(std::string(fn) + ": tol (options[2]) must be >= 0 (0: default)", i);
  if (method == 2.0) {
    if (tol != 0.0 && !(tol == std::floor(tol) && tol >= 8 && tol <= 1024))
      throw LibraryError(std::string(fn) + ": with method 2, options[2] is the sampling grid: a whole number "
                                           "from 8 to 1024 (0: 128)",
                         i);
    o.sampleRes = tol == 0.0 ? 128 : int(tol);
    tol = 0.0;
  }
  o.search.method = method == 1.0 ? ExtremumMethod::Grid : ExtremumMethod::BranchAndBound;
  if (tol > 0.0 && method != 2.0) (method == 1.0 ? o.search.eps : o.search.tolerance) = tol;
  if (v.size() > 2) {
    o.hasBox = true;
    for (size_t d = 0; d < boxDims; ++d) {
      double lo = v[2 + 2 * d].constValue(), hi = v[3 + 2 * d].constValue();
      if (!(lo <= hi) || !std::isfinite(lo) || !std::isfinite(hi))
        throw LibraryError(std::string(fn) + ": box coordinate " + std::to_string(d + 1) +
                               " needs finite lo <= hi (got " + num(lo) + ", " + num(hi) + ")",
                           i);
      o.box.lo.push_back(lo);
      o.box.hi.push_back(hi);
    }
  }
  return o;
}

// Sound bounding box of {f >= 0} within [-kSearchLimit, kSearchLimit]^n by interval subdivision.
Bounds autoBox(const char* fn, const Arg& obj, int argIndex) {
  const uint32_t n = static_cast<uint32_t>(obj.objectDims);
  const std::string give = "; give its box in the options array [method, tol, lo1, hi1, ...]";
  if (n == 0 || n > 6)
    throw LibraryError(std::string(fn) + ": cannot bound object '" + obj.name + "' of " +
                           std::to_string(n) + " coordinates automatically" + give,
                       argIndex);
  TapePtr tape = Tape::compile(obj.value, n);
  IntervalEvaluator ev;
  using Box = std::vector<Interval>;
  std::vector<Box> amb{Box(n, Interval(-kSearchLimit, kSearchLimit))};
  std::vector<double> inLo(n, INFINITY), inHi(n, -INFINITY);  // hull of certified-inside boxes
  const size_t children = size_t{1} << n;
  const size_t kMaxEvals = 400000;
  size_t evals = 0;
  auto hullOf = [&](std::vector<double>& lo, std::vector<double>& hi) {
    lo = inLo;
    hi = inHi;
    for (const Box& b : amb)
      for (uint32_t d = 0; d < n; ++d) {
        lo[d] = std::min(lo[d], b[d].lo);
        hi[d] = std::max(hi[d], b[d].hi);
      }
  };
  std::vector<double> lo, hi;
  for (int level = 0; level < 64 && !amb.empty(); ++level) {
    hullOf(lo, hi);
    // Refined to 1/32 of the extent on every axis, or out of budget: stop.
    bool fine = true;
    for (uint32_t d = 0; d < n; ++d)
      if (amb[0][d].width() > (hi[d] - lo[d]) / 32.0) fine = false;
    if (fine || evals + amb.size() * children > kMaxEvals) break;
    std::vector<Box> next;
    for (const Box& b : amb) {
      for (size_t c = 0; c < children; ++c) {
        Box k(n);
        for (uint32_t d = 0; d < n; ++d) {
          double m = b[d].mid();
          k[d] = (c >> d) & 1 ? Interval(m, b[d].hi) : Interval(b[d].lo, m);
        }
        Interval v = ev.eval(*tape, k.data());
        ++evals;
        if (v.hi < 0.0) continue;  // certified outside
        if (v.lo >= 0.0) {         // certified inside: final
          for (uint32_t d = 0; d < n; ++d) {
            inLo[d] = std::min(inLo[d], k[d].lo);
            inHi[d] = std::max(inHi[d], k[d].hi);
          }
          continue;
        }
        // Inside the inside-hull it cannot widen the result: drop it.
        bool within = true;
        for (uint32_t d = 0; d < n && within; ++d)
          within = k[d].lo >= inLo[d] && k[d].hi <= inHi[d];
        if (!within) next.push_back(std::move(k));
      }
    }
    amb = std::move(next);
  }
  hullOf(lo, hi);
  if (!(lo[0] <= hi[0]))
    throw LibraryError(std::string(fn) + ": object '" + obj.name + "' is empty within ±" +
                           num(kSearchLimit) + " (no point with f >= 0 found)" + give,
                       argIndex);
  for (uint32_t d = 0; d < n; ++d)
    if (lo[d] <= -kSearchLimit || hi[d] >= kSearchLimit)
      throw LibraryError(std::string(fn) + ": object '" + obj.name + "' is not bounded within ±" +
                             num(kSearchLimit) + " (along x[" + std::to_string(d + 1) + "])" + give,
                         argIndex);
  return Bounds{lo, hi};
}

bool hasOptions(std::vector<Arg>& a, size_t fixed) {
  return a.size() == fixed + 1 && a.back().isArray;
}

void checkArgCount(const char* fn, std::vector<Arg>& a, size_t fixed, const char* usage) {
  if (a.size() != fixed && !hasOptions(a, fixed))
    throw LibraryError(std::string(fn) + " takes " + usage + " (got " + std::to_string(a.size()) +
                       " arguments)");
}

// A, B: same dimension n; returns n.
size_t pairDims(const char* fn, const Arg& A, const Arg& B) {
  if (A.objectDims != B.objectDims)
    throw LibraryError(std::string(fn) + ": objects '" + A.name + "' (x[" +
                           std::to_string(A.objectDims) + "]) and '" + B.name + "' (x[" +
                           std::to_string(B.objectDims) + "]) have different dimensions",
                       2);
  return static_cast<size_t>(A.objectDims);
}

Bounds boxOf(const char* fn, const Options& o, const Arg& B, int argIndex) {
  return o.hasBox ? o.box : autoBox(fn, B, argIndex);
}

MinkowskiOptions minkowskiOptions(const Options& o) {
  MinkowskiOptions m;
  static_cast<SearchOptions&>(m) = o.search;
  return m;
}

// fn(x, A, B [, options]) for an operation on two objects of one dimension, searching over B.
template <typename Build>
Expr objectPair(const char* fn, std::vector<Arg>& a, Build build) {
  checkArgCount(fn, a, 3, "(x, A, B [, options])");
  const Arg& A = objectArg(fn, a, 1, "A");
  const Arg& B = objectArg(fn, a, 2, "B");
  size_t n = pairDims(fn, A, B);
  std::vector<Expr>& xs = coordArg(fn, a, n);
  Options o = parseOptions(fn, a, 3, n);
  Bounds bb = boxOf(fn, o, B, 2);
  Expr r = guarded(fn, -1, [&] { return build(A.value, B.value, static_cast<uint32_t>(n), bb, o); });
  return through(r, xs, n);
}

// Basic-set operands (Roerdink-Minkowski, fr_minkowski.h) take the exact algebra instead of
// the search, and so does an exact signed distance (a closed mesh, a polygon, Bezier geometry)
// with a ball (minkowski_algebra/distance_offset.h), and a closed mesh or polytope with a convex
// polytope (mesh_convex_sum.h); the options then do not apply (there is nothing to search).
bool exactPair(std::vector<Arg>& a, bool diff, Expr* out) {
  if (a.size() < 3 || !a[1].isObject || !a[2].isObject || !a[0].isArray || !a[0].array) return false;
  if (diff ? exactMinkowskiDiff(a[1], a[2], *a[0].array, out) : exactMinkowskiSum({&a[1], &a[2]}, *a[0].array, out))
    return true;
  if (a[1].objectDims != 3 || a[2].objectDims != 3 || numParams(a[1].value) > 0 || numParams(a[2].value) > 0 ||
      a[0].array->size() < 3)
    return false;
  Expr r;
  const Expr &A = a[1].value, &B = a[2].value;
  const bool exact = diff ? minkowski::distanceBallDifference(A, B, 3, &r) || minkowski::meshConvexDifference(A, B, 3, &r)
                          : minkowski::distanceBallSum(A, B, 3, &r) || minkowski::meshConvexSum(A, B, 3, &r);
  if (!exact) return false;
  *out = through(r, *a[0].array, 3);
  return true;
}

// Method 2 (options [2, res [, box of the sampled operand]]): the operand that is not a ball or
// a convex polytope is meshed on a res^3 grid and the exact paths run on its mesh
// (minkowski_algebra/sampled_operand.h); the report gives the sampled operand's bound.
bool sampledPair(const char* fn, std::vector<Arg>& a, bool diff, Expr* out) {
  if (a.size() != 4 || !a[3].isArray || !a[3].array || a[3].array->empty() || !(*a[3].array)[0].isConst() ||
      (*a[3].array)[0].constValue() != 2.0)
    return false;
  const Arg& A = objectArg(fn, a, 1, "A");
  const Arg& B = objectArg(fn, a, 2, "B");
  const size_t n = pairDims(fn, A, B);
  std::vector<Expr>& xs = coordArg(fn, a, n);
  const Options o = parseOptions(fn, a, 3, n);
  if (n != 3 || numParams(A.value) > 0 || numParams(B.value) > 0)
    throw LibraryError(std::string(fn) + ": method 2 (a sampled operand) takes two 3D objects without parameters", 3);
  auto exact = [&](const Expr& p, const Expr& q, Expr* r) {
    return diff ? minkowski::distanceBallDifference(p, q, 3, r) || minkowski::meshConvexDifference(p, q, 3, r)
                : minkowski::distanceBallSum(p, q, 3, r) || minkowski::meshConvexSum(p, q, 3, r);
  };
  // The sampled operand is A, or for a sum B when A is the ball or polytope.
  for (int k = 0; k < (diff ? 1 : 2); ++k) {
    const Arg& S = k == 0 ? A : B;
    const Bounds box = o.hasBox ? o.box : autoBox(fn, S, k + 1);
    std::optional<minkowski::SampledOperand> s =
        guarded(fn, 3, [&] { return minkowski::sampleOperand(S.value, box, o.sampleRes, "'" + S.name + "'"); });
    if (!s)
      throw LibraryError(std::string(fn) + ": method 2: '" + S.name + "' has no closed surface inside its box " +
                             "(give the box in the options: [2, res, lo1, hi1, ...])",
                         3);
    Expr r;
    if (k == 0 ? exact(s->field, B.value, &r) : exact(A.value, s->field, &r)) {
      *out = through(r, xs, n);
      return true;
    }
  }
  throw LibraryError(std::string(fn) + ": method 2 needs the other operand to be a ball (frBall, hfSphere) or a "
                                       "convex polytope (hfBlock, planes, a convex mesh)",
                     3);
}

Expr frMinkowski(std::vector<Arg>& a) {
  Expr exact;
  if (exactPair(a, false, &exact)) return exact;
  if (sampledPair("frMinkowski", a, false, &exact)) return exact;
  return objectPair("frMinkowski", a, [](const Expr& A, const Expr& B, uint32_t n, const Bounds& bb, const Options& o) {
    return minkowskiSum(A, B, n, bb, minkowskiOptions(o));
  });
}

// frMinkowskiSum(x, A1, A2, ..., Ak [, options]): A1 ⊕ ... ⊕ Ak; exact when every Ai is in the
// basic set, otherwise folded left by the search ((A1 ⊕ A2) ⊕ A3 ..., nested extremum nodes).
Expr frMinkowskiSum(std::vector<Arg>& a) {
  const char* fn = "frMinkowskiSum";
  const bool opts = !a.empty() && a.back().isArray && a.size() >= 4;
  const size_t end = a.size() - (opts ? 1 : 0);
  if (end < 3) throw LibraryError("frMinkowskiSum takes (x, A1, A2, ... [, options])");
  std::vector<const Arg*> ops;
  for (size_t i = 1; i < end; ++i) ops.push_back(&objectArg(fn, a, static_cast<int>(i), "an operand"));
  for (size_t i = 1; i < ops.size(); ++i) pairDims(fn, *ops[0], *ops[i]);
  const size_t n = static_cast<size_t>(ops[0]->objectDims);
  std::vector<Expr>& xs = coordArg(fn, a, n);
  Expr exact;
  if (exactMinkowskiSum(ops, xs, &exact)) return exact;
  Options o = parseOptions(fn, a, static_cast<int>(end), n);
  if (o.hasBox) throw LibraryError("frMinkowskiSum: the options take no box (each operand's is computed)",
                                   static_cast<int>(end));
  Expr r = ops[0]->value;
  for (size_t i = 1; i < ops.size(); ++i) {
    Expr offset;
    if (n == 3 && (minkowski::distanceBallSum(r, ops[i]->value, 3, &offset) ||
                   minkowski::meshConvexSum(r, ops[i]->value, 3, &offset))) {
      r = offset;
      continue;
    }
    Bounds bb = autoBox(fn, *ops[i], static_cast<int>(i + 1));
    r = guarded(fn, -1, [&] { return minkowskiSum(r, ops[i]->value, static_cast<uint32_t>(n), bb, minkowskiOptions(o)); });
  }
  return through(r, xs, n);
}

Expr frMinkowskiDiff(std::vector<Arg>& a) {
  Expr exact;
  if (exactPair(a, true, &exact)) return exact;
  if (sampledPair("frMinkowskiDiff", a, true, &exact)) return exact;
  return objectPair("frMinkowskiDiff", a,
                    [](const Expr& A, const Expr& B, uint32_t n, const Bounds& bb, const Options& o) {
                      return minkowskiDifference(A, B, n, bb, o.search);
                    });
}

Expr frOffsetR(std::vector<Arg>& a) {
  const char* fn = "frOffsetR";
  checkArgCount(fn, a, 3, "(x, A, r [, options])");
  const Arg& A = objectArg(fn, a, 1, "A");
  size_t n = static_cast<size_t>(A.objectDims);
  std::vector<Expr>& xs = coordArg(fn, a, n);
  double r = constArg(fn, a, 2, "the radius r");
  Options o = parseOptions(fn, a, 3, 0);
  if (o.hasBox) throw LibraryError("frOffsetR: the options take no box", 3);
  Expr res = guarded(fn, 2, [&] { return offsetRadius(A.value, static_cast<uint32_t>(n), r, o.search); });
  return through(res, xs, n);
}

Expr frMorphMinkowski(std::vector<Arg>& a) {
  const char* fn = "frMorphMinkowski";
  checkArgCount(fn, a, 4, "(x, A, B, t [, options])");
  const Arg& A = objectArg(fn, a, 1, "A");
  const Arg& B = objectArg(fn, a, 2, "B");
  size_t n = pairDims(fn, A, B);
  std::vector<Expr>& xs = coordArg(fn, a, n);
  double t = constArg(fn, a, 3, "the time t");
  if (!(t >= 0.0 && t <= 1.0)) throw LibraryError("frMorphMinkowski: t must be in [0, 1]", 3);
  Options o = parseOptions(fn, a, 4, n);
  if (n == 3 && t > 0.0 && t < 1.0 && numParams(A.value) == 0 && numParams(B.value) == 0 && a.size() == 4) {
    // (1 - t) A ⊕ t B (eq. 4.5) without a search where the sum has an exact form; search options
    // given explicitly ask for the search.
    Expr r;
    if (exactMinkowskiMorph(A, B, t, xs, &r)) return r;
    if (minkowski::meshConvexMorph(A.value, B.value, t, &r)) return through(r, xs, n);
  }
  Bounds bb = (t == 0.0 || t == 1.0) ? Bounds{} : boxOf(fn, o, B, 2);
  Expr r = guarded(fn, -1, [&] {
    return morphMinkowski(A.value, B.value, static_cast<uint32_t>(n), t, bb, minkowskiOptions(o));
  });
  return through(r, xs, n);
}

// frProject(x, A, d1, ..., dk [, options]): max over the coordinates d1..dk (1-based) of A.
Expr frProject(std::vector<Arg>& a) {
  const char* fn = "frProject";
  bool opts = a.size() >= 4 && a.back().isArray;
  size_t k = a.size() - 2 - (opts ? 1 : 0);
  if (a.size() < 3 || k == 0)
    throw LibraryError("frProject takes (x, A, d1 [, d2 ...] [, options])");
  const Arg& A = objectArg(fn, a, 1, "A");
  const size_t N = static_cast<size_t>(A.objectDims);
  std::vector<uint32_t> dims;
  for (size_t j = 0; j < k; ++j) {
    int i = static_cast<int>(2 + j);
    double d = constArg(fn, a, i, "a projected coordinate");
    if (d != std::floor(d) || d < 1 || d > static_cast<double>(N))
      throw LibraryError("frProject: coordinate " + num(d) + " is not one of object '" + A.name +
                             "''s x[1.." + std::to_string(N) + "]",
                         i);
    uint32_t di = static_cast<uint32_t>(d) - 1;
    if (std::find(dims.begin(), dims.end(), di) != dims.end())
      throw LibraryError("frProject: coordinate " + num(d) + " is given twice", i);
    dims.push_back(di);
  }
  if (k >= N)
    throw LibraryError("frProject: projecting all " + std::to_string(N) + " coordinates of object '" +
                           A.name + "' leaves none",
                       2);
  std::vector<Expr>& xs = coordArg(fn, a, N - k);
  Options o = parseOptions(fn, a, opts ? static_cast<int>(a.size() - 1) : static_cast<int>(a.size()), k);
  Bounds box;
  if (o.hasBox) {
    box = o.box;
  } else {
    Bounds full = autoBox(fn, A, 1);
    for (uint32_t d : dims) {
      box.lo.push_back(full.lo[d]);
      box.hi.push_back(full.hi[d]);
    }
  }
  Expr r = guarded(fn, -1, [&] { return project(A.value, static_cast<uint32_t>(N), dims, box, o.search); });
  return through(r, xs, N - k);
}

// frSweep(x, A, T1, ..., Tn [, R...], t0, t1 [, options]): T, R are objects of one coordinate
// (the time); A is time-varying when it has one more coordinate than x (its last one is t).
Expr frSweep(std::vector<Arg>& a) {
  const char* fn = "frSweep";
  bool opts = !a.empty() && a.back().isArray && a.size() >= 6;
  size_t end = a.size() - (opts ? 1 : 0);  // one past t1
  if (end < 5)
    throw LibraryError("frSweep takes (x, A, T1, ..., Tn [, R1 (2D) | R1, R2, R3 (3D)], t0, t1 [, options])");
  const Arg& A = objectArg(fn, a, 1, "A");
  if (!a[0].isArray || !a[0].array)
    throw LibraryError("frSweep: argument 1 must be the coordinate array (x)", 0);
  const size_t xsize = a[0].array->size();
  const size_t N = static_cast<size_t>(A.objectDims);
  const bool timeVarying = N == xsize + 1;
  const size_t n = timeVarying ? N - 1 : N;
  if (n < 1 || n > 3)
    throw LibraryError("frSweep: object '" + A.name + "' must have 1, 2 or 3 coordinates (plus time)", 1);
  std::vector<Expr>& xs = coordArg(fn, a, n);
  const size_t motions = end - 4;
  const size_t rot = n == 2 ? 1 : n == 3 ? 3 : 0;
  if (motions != n && motions != n + rot)
    throw LibraryError("frSweep: " + std::to_string(n) + "D motion needs " + std::to_string(n) +
                           " translation objects" +
                           (rot ? " (then optionally " + std::to_string(rot) + " rotation objects)" : "") +
                           ", got " + std::to_string(motions),
                       2);
  Motion m;
  for (size_t j = 0; j < motions; ++j) {
    int i = static_cast<int>(2 + j);
    const Arg& M = objectArg(fn, a, i, "a motion component");
    if (M.objectDims != 1)
      throw LibraryError("frSweep: motion object '" + M.name + "' must have x[1] (the time), not x[" +
                             std::to_string(M.objectDims) + "]",
                         i);
    (j < n ? m.translation : m.rotation).push_back(M.value);
  }
  double t0 = constArg(fn, a, static_cast<int>(end - 2), "t0");
  double t1 = constArg(fn, a, static_cast<int>(end - 1), "t1");
  if (!(t0 <= t1)) throw LibraryError("frSweep: need t0 <= t1", static_cast<int>(end - 1));
  Options o = parseOptions(fn, a, static_cast<int>(end), 0);
  if (o.hasBox) throw LibraryError("frSweep: the options take no box", static_cast<int>(end));
  Expr r = guarded(fn, -1, [&] { return sweep(A.value, static_cast<uint32_t>(n), m, t0, t1, o.search); });
  return through(r, xs, n);
}

// ---- Keyframe motions ------------------------------------------------------------------
// Piecewise-linear interpolation through keyframes (t_i, v_i), i = 1..k, t_i strictly
// increasing constants; held at v_1 before t_1 and at v_k after t_k. Written as a sum of clamped
// ramps, v_1 + sum_i s_i (clamp(t, t_i, t_{i+1}) - t_i) with s_i the segment slopes: continuous,
// no branches, and on a t interval inside one segment its natural interval enclosure is exact
// (the other clamps are constant there), which keeps the sweep's branch-and-bound over t tight.
// Piecewise linear rather than Catmull-Rom: the path passes through the keyframes and stays in
// their convex hull (no overshoot), and a ball swept along it is exactly a union of capsules.
Expr keyframeLerp(const Expr& t, const std::vector<double>& ts, const std::vector<Expr>& vs) {
  Expr r = vs[0];
  for (size_t i = 0; i + 1 < ts.size(); ++i) {
    Expr dv = vs[i + 1] - vs[i];
    if (dv.isConst(0.0)) continue;  // a constant stretch adds nothing
    Expr ramp = min(max(t, Expr(ts[i])), Expr(ts[i + 1])) - ts[i];
    r = r + dv * (1.0 / (ts[i + 1] - ts[i])) * ramp;
  }
  return r;
}

// The keyframe times: an array of k >= minKeys constants, strictly increasing.
std::vector<double> keyTimes(const char* fn, std::vector<Arg>& a, int i, size_t minKeys) {
  if (i >= static_cast<int>(a.size()) || !a[i].isArray || !a[i].array)
    throw LibraryError(std::string(fn) + ": argument " + std::to_string(i + 1) +
                           " must be the array of keyframe times",
                       i);
  const std::vector<Expr>& v = *a[i].array;
  if (v.size() < minKeys)
    throw LibraryError(std::string(fn) + ": the times array '" + a[i].name + "' needs at least " +
                           std::to_string(minKeys) + " keyframes (got " + std::to_string(v.size()) + ")",
                       i);
  std::vector<double> ts;
  for (size_t k = 0; k < v.size(); ++k) {
    if (!v[k].isConst() || !std::isfinite(v[k].constValue()))
      throw LibraryError(std::string(fn) + ": time " + a[i].name + "[" + std::to_string(k + 1) +
                             "] must be a finite constant known at compile time",
                         i);
    ts.push_back(v[k].constValue());
    if (k > 0 && !(ts[k] > ts[k - 1]))
      throw LibraryError(std::string(fn) + ": keyframe times must increase strictly (" + a[i].name +
                             "[" + std::to_string(k) + "] = " + num(ts[k - 1]) + ", " + a[i].name + "[" +
                             std::to_string(k + 1) + "] = " + num(ts[k]) + ")",
                         i);
  }
  return ts;
}

// frKeyframe(t, times, values): the piecewise-linear function through (times[i], values[i]);
// use it in a motion object of frSweep (px(x[1], a[1]) { ...; px = frKeyframe(x[1], ts, vs); }).
Expr frKeyframe(std::vector<Arg>& a) {
  const char* fn = "frKeyframe";
  if (a.size() != 3) throw LibraryError("frKeyframe takes (t, times, values)");
  const Expr& t = hf::scalarArg(fn, a, 0);
  std::vector<double> ts = keyTimes(fn, a, 1, 1);
  const std::vector<Expr>& vs = hf::arrayExactly(fn, a, 2, ts.size(), " (one value per keyframe time)");
  return keyframeLerp(t, ts, vs);
}

// frSweepKeys(x, A, times, positions [, angles] [, options]): A moved through k keyframes,
// positions = k n-vectors one after the other, angles = k rotations (2D: one angle; 3D: Rx Ry
// Rz), interpolated piecewise linearly, swept over t in [times[1], times[k]].
Expr frSweepKeys(std::vector<Arg>& a) {
  const char* fn = "frSweepKeys";
  const char* usage = "frSweepKeys takes (x, A, times, positions [, angles] [, options])";
  if (a.size() < 4 || a.size() > 6) throw LibraryError(usage);
  const Arg& A = objectArg(fn, a, 1, "A");
  if (!a[0].isArray || !a[0].array)
    throw LibraryError("frSweepKeys: argument 1 must be the coordinate array (x)", 0);
  const size_t N = static_cast<size_t>(A.objectDims);
  const bool timeVarying = N == a[0].array->size() + 1;
  const size_t n = timeVarying ? N - 1 : N;
  if (n < 1 || n > 3)
    throw LibraryError("frSweepKeys: object '" + A.name + "' must have 1, 2 or 3 coordinates (plus time)", 1);
  std::vector<Expr>& xs = coordArg(fn, a, n);
  std::vector<double> ts = keyTimes(fn, a, 2, 2);
  const size_t k = ts.size();
  const std::vector<Expr>& ps =
      hf::arrayExactly(fn, a, 3, k * n, " (" + std::to_string(n) + " coordinates for each of the " +
                                           std::to_string(k) + " keyframes)");
  const size_t rot = n == 2 ? 1 : n == 3 ? 3 : 0;
  // A fifth array is the angles when its size is k * rot (2D with two keyframes: always the
  // angles; give [0, 0] then to pass options), otherwise the options.
  int anglesAt = -1, optionsAt = -1;
  if (rot == 0 && a.size() == 6)
    throw LibraryError("frSweepKeys: a 1D motion takes no angles: (x, A, times, positions [, options])", 4);
  for (int i = 4; i < static_cast<int>(a.size()); ++i) {
    if (!a[i].isArray || !a[i].array)
      throw LibraryError(std::string(fn) + ": argument " + std::to_string(i + 1) +
                             " must be an array (angles or options)",
                         i);
    if (i == 4 && rot > 0 && a[i].array->size() == k * rot)
      anglesAt = i;
    else if (i == static_cast<int>(a.size()) - 1 && a[i].array->size() == 2)
      optionsAt = i;
    else if (i == static_cast<int>(a.size()) - 1 && i == 5)
      optionsAt = i;  // parseOptions explains the size
    else if (rot == 0)
      optionsAt = i;  // 1D: only options; parseOptions explains the size
    else
      throw LibraryError(std::string(fn) + ": array " + a[i].name + " must be the angles (" + std::to_string(rot) +
                             " for each of the " + std::to_string(k) + " keyframes: " + std::to_string(k * rot) +
                             " elements) or the options [method, tol] (got " + std::to_string(a[i].array->size()) +
                             " elements)",
                         i);
  }
  for (size_t j = 0; j < k * n; ++j)
    if (numVars(ps[j]) > 0 || numParams(ps[j]) > 0)
      throw LibraryError(std::string(fn) + ": position " + a[3].name + "[" + std::to_string(j + 1) +
                             "] must not depend on x or a free a[] (use frKeyframe in motion objects and frSweep)",
                         3);
  Motion m;
  const Expr t = Expr::x(0);
  auto channel = [&](const std::vector<Expr>& v, size_t stride, size_t c) {
    std::vector<Expr> vs;
    for (size_t j = 0; j < k; ++j) vs.push_back(v[j * stride + c]);
    return keyframeLerp(t, ts, vs);
  };
  for (size_t c = 0; c < n; ++c) m.translation.push_back(channel(ps, n, c));
  if (anglesAt >= 0) {
    const std::vector<Expr>& an = *a[anglesAt].array;
    for (size_t j = 0; j < an.size(); ++j)
      if (numVars(an[j]) > 0 || numParams(an[j]) > 0)
        throw LibraryError(std::string(fn) + ": angle " + a[anglesAt].name + "[" + std::to_string(j + 1) +
                               "] must not depend on x or a free a[]",
                           anglesAt);
    for (size_t c = 0; c < rot; ++c) m.rotation.push_back(channel(an, rot, c));
  }
  Options o = optionsAt >= 0 ? parseOptions(fn, a, optionsAt, 0) : Options{};
  if (o.hasBox) throw LibraryError("frSweepKeys: the options take no box", optionsAt);
  // A ball or polytope(s) moved by translation only sweeps a union of capsules or convex hulls
  // (minkowski_algebra/path_sweep.h): no search, the options do not apply.
  Expr exact;
  if (n == 3 && !timeVarying && anglesAt < 0 && numParams(A.value) == 0 && minkowski::keyframeSweep(A.value, ps, &exact))
    return through(exact, xs, n);
  Expr r = guarded(fn, -1, [&] { return sweep(A.value, static_cast<uint32_t>(n), m, ts.front(), ts.back(), o.search); });
  return through(r, xs, n);
}

// Relations as compile-time constants (Pasko-Survey, relations; Vyatkin-Perturbation, collision
// detection by recursive subdivision; core relations.h, as `frep relate` runs them):
//   frIntersects(A, B [, o])  1: a common point (fa >= 0 and fb >= 0) was found; 0: proved
//                             disjoint; -1: undecided (touching, or closer than the smallest box)
//   frInside(A, B [, o])      1: A proved inside B's interior (A meets no point with fb <= 0);
//                             0: a point of A with fb <= 0 was found; -1: undecided
// o = [lo1, hi1, ..., lon, hin [, minSize]] (constants): the box searched; by default the
// intersection of the two automatic boxes (frIntersects) or A's automatic box (frInside), which
// contain every point that matters; minSize defaults to 1e-4 of the box's largest edge.
Expr relation(const char* fn, std::vector<Arg>& a, bool inside) {
  if (a.size() != 2 && !(a.size() == 3 && a[2].isArray))
    throw LibraryError(std::string(fn) + " takes (A, B [, o]) (got " + std::to_string(a.size()) + " arguments)");
  const Arg& A = objectArg(fn, a, 0, "A");
  const Arg& B = objectArg(fn, a, 1, "B");
  if (A.objectDims != B.objectDims)
    throw LibraryError(std::string(fn) + ": objects '" + A.name + "' and '" + B.name + "' have different dimensions", 1);
  const size_t n = static_cast<size_t>(A.objectDims);
  std::vector<Interval> box(n);
  double minSize = 0.0;
  if (a.size() == 3) {
    std::vector<Expr>& v = *a[2].array;
    if (v.size() != 2 * n && v.size() != 2 * n + 1)
      throw LibraryError(std::string(fn) + ": the options array needs " + std::to_string(2 * n) + " or " +
                             std::to_string(2 * n + 1) + " elements [lo1, hi1, ..., minSize] (got " +
                             std::to_string(v.size()) + ")",
                         2);
    for (size_t k = 0; k < v.size(); ++k)
      if (!v[k].isConst()) throw LibraryError(std::string(fn) + ": the options must be constants", 2);
    for (size_t d = 0; d < n; ++d) {
      double lo = v[2 * d].constValue(), hi = v[2 * d + 1].constValue();
      if (!(lo <= hi) || !std::isfinite(lo) || !std::isfinite(hi))
        throw LibraryError(std::string(fn) + ": box coordinate " + std::to_string(d + 1) + " needs finite lo <= hi", 2);
      box[d] = Interval(lo, hi);
    }
    if (v.size() == 2 * n + 1) minSize = v[2 * n].constValue();
  } else {
    Bounds ba = autoBox(fn, A, 0);
    for (size_t d = 0; d < n; ++d) box[d] = Interval(ba.lo[d], ba.hi[d]);
    if (!inside) {
      Bounds bb = autoBox(fn, B, 1);
      for (size_t d = 0; d < n; ++d) {
        double lo = std::max(ba.lo[d], bb.lo[d]), hi = std::min(ba.hi[d], bb.hi[d]);
        if (!(lo <= hi)) return Expr(0.0);  // the sound enclosures do not meet
        box[d] = Interval(lo, hi);
      }
    }
  }
  double extent = 0.0;
  for (const Interval& iv : box) extent = std::max(extent, iv.width());
  if (!(minSize > 0.0)) minSize = extent > 0.0 ? 1e-4 * extent : 1e-9;
  const uint32_t dims = static_cast<uint32_t>(n);
  TapePtr ta = Tape::compile(A.value, dims);
  TapePtr tb = Tape::compile(inside ? -B.value : B.value, dims);
  IntersectionResult r = mayIntersect(*ta, *tb, box.data(), minSize);
  // Inside: A meets {-fb >= 0} (a point of A not in B's interior) disproves it.
  if (inside) return Expr(r.contact == Contact::Disjoint ? 1.0 : r.contact == Contact::Intersecting ? 0.0 : -1.0);
  return Expr(r.contact == Contact::Intersecting ? 1.0 : r.contact == Contact::Disjoint ? 0.0 : -1.0);
}

Expr frIntersects(std::vector<Arg>& a) { return relation("frIntersects", a, false); }
Expr frInside(std::vector<Arg>& a) { return relation("frInside", a, true); }

const bool registered = registerAll({
    {"frMinkowski", "*", "A + B: max over u in box(B) of A(X - u) & B(u)", frMinkowski},
    {"frMinkowskiSum", "*", "A1 + A2 + ... + Ak: exact algebra for basic-set operands, else folded searches", frMinkowskiSum},
    {"frMinkowskiDiff", "*", "A - B: min over u in box(B) of max(A(X + u), -B(u))", frMinkowskiDiff},
    {"frOffsetR", "*", "r > 0: max over |u| <= r of A(X + u); r < 0: min", frOffsetR},
    {"frMorphMinkowski", "*", "((1 - t) A) + (t B), t in [0, 1] constant", frMorphMinkowski},
    {"frProject", "*", "max over the given coordinates (1-based) of A", frProject},
    {"frSweep", "*", "max over t in [t0, t1] of A(M(t)^-1 X), M from motion objects of t", frSweep},
    {"frSweepKeys", "*", "frSweep along keyframes: (x, A, times, positions [, angles] [, options])", frSweepKeys},
    {"frIntersects", "*", "1 / 0 / -1: objects A and B proved to intersect / proved disjoint / undecided (constant)", frIntersects},
    {"frInside", "*", "1 / 0 / -1: object A proved inside B's interior / a point of A outside it found / undecided (constant)", frInside},
    {"frKeyframe", "*", "piecewise-linear interpolation through (times[i], values[i]) at t", frKeyframe},
});

}  // namespace
}  // namespace frep::lang
