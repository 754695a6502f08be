// frep eval: f, its class (in/on/out) and its gradient at one point.
#include <cmath>
#include <iostream>

#include "arg_parse.h"
#include "commands.h"
#include "exit_codes.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/tape.h"

namespace frep::cli {

int runEval(const EvalRequest& request) {
  if (!(request.tolerance >= 0.0)) throw badArgs("--tolerance: expected a number >= 0");
  LoadedModel m = loadModel(request.model, false);
  const std::string count = std::to_string(m.dims);
  std::vector<double> at = parseNumbers("--at", request.at, count);
  if (int(at.size()) != m.dims)
    throw badArgs("--at: expected " + count + " comma-separated numbers (one per coordinate of '" +
                  m.model.objectName + "'), got '" + request.at + "'");

  TapePtr tape = Tape::compile(m.field, uint32_t(m.dims));
  PointEvaluator point;
  DomainCounts domain;
  point.countDomainErrors(&domain);
  const double value = point.eval(*tape, at.data());
  std::vector<double> grad(tape->numVars());
  GradientEvaluator gradient;
  gradient.eval(*tape, at.data(), grad.data());

  const char* status = std::isnan(value)                         ? "out (NaN: a domain error, counted as outside)"
                       : std::abs(value) <= request.tolerance ? "on"
                       : value > 0.0                             ? "in"
                                                                 : "out";
  std::cout << "object: " << m.model.objectName << "\n";
  std::cout << "value: " << formatNumber(value) << "\n";
  std::cout << "status: " << status << "\n";
  std::cout << "gradient:";
  for (int i = 0; i < m.dims; ++i) std::cout << (i ? ", " : " ") << formatNumber(grad[size_t(i)]);
  std::cout << "\n";
  if (domain.total())
    std::cout << "domain errors: " << domain.describe() << " (documented values used, see docs/language.md)\n";
  return kExitOk;
}

}  // namespace frep::cli
