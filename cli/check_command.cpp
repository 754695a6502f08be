// frep check: compile only; diagnostics go to stderr (by loadModel), the objects to stdout.
// Then a coarse look at the values: a model that is NaN, or hits a domain error, at every point
// of a small grid over its box compiles but has no solid to show (hfp stops at such points).
#include <cmath>
#include <iostream>

#include "arg_parse.h"
#include "commands.h"
#include "exit_codes.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/tape.h"

namespace frep::cli {
namespace {

constexpr int kCheckPoints = 17;  // per axis: 17^3 = 4913 evaluations, milliseconds

// The selected object with x[4..] held at 0 and a[] = 0 (as frep mesh sees it by default).
Expr viewField(const LoadedModel& m) {
  if (m.dims <= 3) return m.field;
  lang::FieldSpec spec = m.spec;
  spec.axis.clear();
  spec.constant.clear();
  for (int i = 0; i < m.model.xSize; ++i) {
    spec.axis.push_back(i < 3 ? i : -1);
    spec.constant.push_back(0.0);
  }
  return lang::fieldOf(m.model, spec);
}

std::string boxText(const Box& b, int dims) {
  std::string s;
  for (int a = 0; a < dims; ++a)
    s += std::string(a ? " x " : "") + "[" + formatNumber(b.lo[size_t(a)]) + ", " + formatNumber(b.hi[size_t(a)]) + "]";
  return s;
}

void warnIfNoValues(const ModelRequest& request, const LoadedModel& m, const std::string& bounds) {
  const Box box = bounds.empty() ? Box{} : parseBounds("-b/--bounds", bounds);
  const int dims = std::min(m.dims, 3);
  const Expr f = viewField(m);
  auto tape = Tape::compile(f, uint32_t(std::max(dims, 1)));
  PointEvaluator ev;
  DomainCounts all, one;
  uint64_t points = 0, nan = 0, erroring = 0;
  const int n[3] = {kCheckPoints, dims > 1 ? kCheckPoints : 1, dims > 2 ? kCheckPoints : 1};
  double x[3] = {0, 0, 0};
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const int idx[3] = {i, j, k};
        for (int a = 0; a < dims; ++a)
          x[a] = box.lo[size_t(a)] + (box.hi[size_t(a)] - box.lo[size_t(a)]) * idx[a] / (kCheckPoints - 1);
        one = DomainCounts{};
        ev.countDomainErrors(&one);
        const double v = ev.eval(*tape, x);
        ++points;
        nan += std::isnan(v);
        erroring += one.total() > 0;
        all.add(one);
      }
  const std::string where = "'" + m.model.objectName + "' at all " + std::to_string(points) +
                            " points of a grid over " + boxText(box, dims) + " (-b)";
  if (nan == points)
    std::cerr << request.path << ": warning: " << where << " is NaN: the solid is empty"
              << (all.total() ? " (domain errors: " + all.describe() + ")" : "") << "\n";
  else if (erroring == points)
    std::cerr << request.path << ": warning: " << where << " hits a domain error (" << all.describe()
              << "); hfp stops evaluating at such points, frepfarm uses the values of docs/language.md\n";
}

}  // namespace

int runCheck(const ModelRequest& model, const std::string& bounds) {
  LoadedModel m = loadModel(model, false);
  std::cout << model.path << ": ok, " << m.objects.size() << (m.objects.size() == 1 ? " object" : " objects")
            << "\n";
  for (const lang::ObjectInfo& o : m.objects) {
    std::cout << "  " << o.name << "(x[" << o.xSize << "], a[" << o.aSize << "]";
    if (o.sSize > 0) std::cout << ", s[" << o.sSize << "]";
    std::cout << ")  line " << o.line << (o.name == m.model.objectName ? "  (selected)" : "") << "\n";
  }
  warnIfNoValues(model, m, bounds);
  return kExitOk;
}

}  // namespace frep::cli
