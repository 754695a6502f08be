// frep relate A.hf B.hf: relations between two solids (Pasko-Survey, relations; Vyatkin-
// Perturbation, collision detection by recursive subdivision), certified by interval
// arithmetic over the box: intersection (collision) and inclusion A ⊂ B, each yes / no /
// undecided with a witness point, plus point membership with --at. Core: relations.h.
#include <chrono>
#include <iostream>

#include "arg_parse.h"
#include "commands.h"
#include "exit_codes.h"
#include "frep/expressions/tape.h"
#include "frep/relations/relations.h"

namespace frep::cli {
namespace {

std::string pointText(const std::vector<double>& p) {
  std::string s = "(";
  for (size_t i = 0; i < p.size(); ++i) s += (i ? ", " : "") + formatNumber(p[i]);
  return s + ")";
}

const char* membershipName(Membership m) {
  return m == Membership::In ? "inside" : m == Membership::On ? "on the surface" : "outside";
}

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int runRelate(const RelateRequest& request) {
  LoadedModel a = loadModel(request.a, true), b = loadModel(request.b, true);
  const Box box = request.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.bounds);
  double extent = 0;
  for (int i = 0; i < 3; ++i) extent = std::max(extent, box.hi[size_t(i)] - box.lo[size_t(i)]);
  const double minSize = request.minSize > 0 ? request.minSize : extent * 1e-4;
  if (!(request.minSize >= 0)) throw badArgs("--min-size must be >= 0, got " + formatNumber(request.minSize));
  const uint32_t dims = 3;
  auto ta = Tape::compile(a.field, dims), tb = Tape::compile(b.field, dims);
  auto notB = Tape::compile(-b.field, dims);
  std::vector<Interval> ibox;
  for (int i = 0; i < 3; ++i) ibox.push_back(Interval(box.lo[size_t(i)], box.hi[size_t(i)]));

  std::cout << "A = " << request.a.path << " ('" << a.model.objectName << "'), B = " << request.b.path << " ('"
            << b.model.objectName << "'), box " << pointText({box.lo[0], box.lo[1], box.lo[2]}) << " to "
            << pointText({box.hi[0], box.hi[1], box.hi[2]}) << ", smallest box " << formatNumber(minSize) << "\n";
  if (!request.at.empty()) {
    std::vector<double> p = parseNumbers("--at", request.at, "3");
    if (p.size() != 3) throw badArgs("--at needs 3 values, got '" + request.at + "'");
    std::cout << "point " << pointText(p) << ": " << membershipName(classifyPoint(*ta, p.data(), request.tolerance))
              << " A, " << membershipName(classifyPoint(*tb, p.data(), request.tolerance)) << " B\n";
  }

  // Intersection: a common point (fa >= 0 and fb >= 0) or a proof that none is in the box.
  auto t0 = std::chrono::steady_clock::now();
  IntersectionResult x = mayIntersect(*ta, *tb, ibox.data(), minSize);
  double tx = secondsSince(t0);
  std::cout << "intersect: "
            << (x.contact == Contact::Intersecting ? "yes, common point " + pointText(x.witness)
                : x.contact == Contact::Disjoint   ? std::string("no (proved disjoint in the box)")
                                                   : std::string("undecided (touching or closer than the smallest box)"))
            << "; " << x.boxesVisited << " boxes, " << formatNumber(tx) << " s\n";

  // Inclusion A ⊂ B: A meets no point where fb <= 0 (A ∩ {-fb >= 0} empty): then A lies in B's
  // interior. A point of A with fb <= 0 disproves interior inclusion.
  t0 = std::chrono::steady_clock::now();
  IntersectionResult in = mayIntersect(*ta, *notB, ibox.data(), minSize);
  double tin = secondsSince(t0);
  std::cout << "A inside B: "
            << (in.contact == Contact::Disjoint       ? std::string("yes (proved in the box)")
                : in.contact == Contact::Intersecting ? "no, point of A not inside B " + pointText(in.witness)
                                                      : std::string("undecided (A reaches B's surface)"))
            << "; " << in.boxesVisited << " boxes, " << formatNumber(tin) << " s\n";
  return kExitOk;
}

}  // namespace frep::cli
