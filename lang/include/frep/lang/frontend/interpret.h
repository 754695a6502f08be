// A direct tree-walking interpreter of HyperFun objects, one point at a time, in doubles: the
// baseline that compiled models are benchmarked against, and an independent oracle for the
// lowering in tests. It accepts only models that compile, and its semantics are the compiled
// ones (docs/language.md). One approximation: an exponent within 1e-6 above an integer counts
// as that integer when it is written as a literal; the compiler does so for every exponent that
// folds to a constant (e.g. one computed from loop counters).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "frep/lang/frontend/ast.h"
#include "frep/lang/hyperfun.h"

namespace frep::lang {

struct InterpretError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Interpreter {
 public:
  // Parses the source; throws InterpretError unless it compiles without errors.
  explicit Interpreter(const std::string& source, const CompileOptions& options = {});

  // f at one point, for the object chosen as compile() chooses it. Library functions run
  // through their lowering with constant arguments (correct, but not fast).
  double eval(const std::vector<double>& x, const std::vector<double>& a) const;

  const std::string& objectName() const { return selected_; }

 private:
  Program program_;
  CompileOptions options_;
  std::string selected_;
};

}  // namespace frep::lang
