// frep relate A.hf B.hf: relations between two solids (Pasko-Survey, relations; Vyatkin-
// Perturbation, collision detection by recursive subdivision), certified by interval
// arithmetic over the box: intersection (collision) and inclusion A ⊂ B, each yes / no /
// undecided with a witness point, the clearance (minimum distance) and penetration depth as
// lower and upper bounds with witnesses, plus point membership with --at. Core: relations.h,
// clearance.h.
#include <chrono>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

#include "arg_parse.h"
#include "commands.h"
#include "exit_codes.h"
#include "frep/expressions/tape.h"
#include "frep/relations/clearance.h"
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

const char* contactName(Contact c) {
  return c == Contact::Intersecting ? "yes" : c == Contact::Disjoint ? "no" : "undecided";
}

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

std::string boundText(double lo, double hi) { return "[" + formatNumber(lo) + ", " + formatNumber(hi) + "]"; }

}  // namespace

int runRelate(const RelateRequest& request) {
  LoadedModel a = loadModel(request.a, true), b = loadModel(request.b, true);
  const Box box = request.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.bounds);
  double extent = 0;
  for (int i = 0; i < 3; ++i) extent = std::max(extent, box.hi[size_t(i)] - box.lo[size_t(i)]);
  const double minSize = request.minSize > 0 ? request.minSize : extent * 1e-4;
  if (!(request.minSize >= 0)) throw badArgs("--min-size must be >= 0, got " + formatNumber(request.minSize));
  if (!(request.distanceTol >= 0) || !std::isfinite(request.distanceTol))
    throw badArgs("--distance-tol must be >= 0 (0: 1e-3 of the box), got " + formatNumber(request.distanceTol));
  const uint32_t dims = 3;
  auto ta = Tape::compile(a.field, dims), tb = Tape::compile(b.field, dims);
  auto notB = Tape::compile(-b.field, dims);
  std::vector<Interval> ibox;
  for (int i = 0; i < 3; ++i) ibox.push_back(Interval(box.lo[size_t(i)], box.hi[size_t(i)]));

  nlohmann::json out;
  out["a"] = {{"path", request.a.path}, {"object", a.model.objectName}};
  out["b"] = {{"path", request.b.path}, {"object", b.model.objectName}};
  out["box"] = {{"lo", {box.lo[0], box.lo[1], box.lo[2]}}, {"hi", {box.hi[0], box.hi[1], box.hi[2]}}};
  std::ostream& text = std::cout;
  const bool json = request.json;
  if (!json)
    text << "A = " << request.a.path << " ('" << a.model.objectName << "'), B = " << request.b.path << " ('"
         << b.model.objectName << "'), box " << pointText({box.lo[0], box.lo[1], box.lo[2]}) << " to "
         << pointText({box.hi[0], box.hi[1], box.hi[2]}) << ", smallest box " << formatNumber(minSize) << "\n";
  if (!request.at.empty()) {
    std::vector<double> p = parseNumbers("--at", request.at, "3");
    if (p.size() != 3) throw badArgs("--at needs 3 values, got '" + request.at + "'");
    const Membership ma = classifyPoint(*ta, p.data(), request.tolerance);
    const Membership mb = classifyPoint(*tb, p.data(), request.tolerance);
    out["point"] = {{"at", p}, {"a", membershipName(ma)}, {"b", membershipName(mb)}};
    if (!json) text << "point " << pointText(p) << ": " << membershipName(ma) << " A, " << membershipName(mb) << " B\n";
  }

  // Intersection: a common point (fa >= 0 and fb >= 0) or a proof that none is in the box.
  auto t0 = std::chrono::steady_clock::now();
  IntersectionResult x = mayIntersect(*ta, *tb, ibox.data(), minSize);
  double tx = secondsSince(t0);
  out["intersect"] = {{"answer", contactName(x.contact)}, {"boxes", x.boxesVisited}, {"seconds", tx}};
  if (x.contact == Contact::Intersecting) out["intersect"]["witness"] = x.witness;
  if (!json)
    text << "intersect: "
         << (x.contact == Contact::Intersecting ? "yes, common point " + pointText(x.witness)
             : x.contact == Contact::Disjoint   ? std::string("no (proved disjoint in the box)")
                                                : std::string("undecided (touching or closer than the smallest box)"))
         << "; " << x.boxesVisited << " boxes, " << formatNumber(tx) << " s\n";

  // Inclusion A ⊂ B: A meets no point where fb <= 0 (A ∩ {-fb >= 0} empty): then A lies in B's
  // interior. A point of A with fb <= 0 disproves interior inclusion.
  t0 = std::chrono::steady_clock::now();
  IntersectionResult in = mayIntersect(*ta, *notB, ibox.data(), minSize);
  double tin = secondsSince(t0);
  out["inside"] = {{"answer", in.contact == Contact::Disjoint       ? "yes"
                              : in.contact == Contact::Intersecting ? "no"
                                                                    : "undecided"},
                   {"boxes", in.boxesVisited},
                   {"seconds", tin}};
  if (in.contact == Contact::Intersecting) out["inside"]["witness"] = in.witness;
  if (!json)
    text << "A inside B: "
         << (in.contact == Contact::Disjoint       ? std::string("yes (proved in the box)")
             : in.contact == Contact::Intersecting ? "no, point of A not inside B " + pointText(in.witness)
                                                   : std::string("undecided (A reaches B's surface)"))
         << "; " << in.boxesVisited << " boxes, " << formatNumber(tin) << " s\n";

  // Clearance: 0 with the common point when they meet, else enclosed by clearance().
  const double dtol = request.distanceTol > 0 ? request.distanceTol : extent * 1e-3;
  if (x.contact == Contact::Intersecting) {
    out["clearance"] = {{"lower", 0.0},           {"upper", 0.0},      {"witness_a", x.witness},
                        {"witness_b", x.witness}, {"converged", true}, {"pairs", 0}};
    if (!json) text << "clearance: 0 (they meet at the common point)\n";
  } else {
    ClearanceOptions co;
    co.tolerance = dtol;
    t0 = std::chrono::steady_clock::now();
    ClearanceResult c = clearance(*ta, *tb, ibox.data(), co);
    const double tc = secondsSince(t0);
    if (c.emptyA || c.emptyB) {
      out["clearance"] = nullptr;
      if (!json) text << "clearance: none (" << (c.emptyA ? "A" : "B") << " has no point in the box)\n";
    } else {
      out["clearance"] = {
          {"lower", number(c.lower)}, {"upper", number(c.upper)}, {"witness_a", c.a}, {"witness_b", c.b},
          {"converged", c.converged}, {"pairs", c.pairs},         {"seconds", tc}};
      if (!json)
        text << "clearance: " << boundText(c.lower, c.upper) << (c.converged ? "" : " (not converged)") << ", points "
             << pointText(c.a) << " of A and " << pointText(c.b) << " of B; " << c.pairs << " box pairs, "
             << formatNumber(tc) << " s\n";
    }
  }

  // Penetration depth: only solids that meet (or may) overlap.
  if (x.contact == Contact::Disjoint) {
    out["penetration"] = {{"lower", 0.0}, {"upper", 0.0}, {"translation", {0.0, 0.0, 0.0}}, {"converged", true}};
    if (!json) text << "penetration: 0 (disjoint)\n";
  } else {
    PenetrationOptions po;
    po.tolerance = dtol;
    t0 = std::chrono::steady_clock::now();
    PenetrationResult p = penetration(a.field, b.field, dims, ibox.data(), po);
    const double tp = secondsSince(t0);
    out["penetration"] = {{"lower", number(p.lower)}, {"upper", number(p.upper)}, {"translation", p.translation},
                          {"converged", p.converged}, {"boxes", p.boxes},         {"seconds", tp}};
    if (!json) {
      text << "penetration: " << boundText(p.lower, p.upper) << (p.converged ? "" : " (not converged)");
      if (!p.translation.empty()) text << ", A moved by " << pointText(p.translation) << " is proved clear of B";
      text << "; " << p.boxes << " translation boxes, " << formatNumber(tp) << " s\n";
    }
  }
  if (json) std::cout << out.dump() << "\n";
  return kExitOk;
}

}  // namespace frep::cli
