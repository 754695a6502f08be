// Lowering: runs each object's statements symbolically and produces its field as a core Expr.
#pragma once

#include <vector>

#include "frep/expr.h"
#include "frep/lang/ast.h"
#include "frep/lang/diagnostics.h"
#include "frep/lang/hyperfun.h"

namespace frep::lang {

struct LoweredObject {
  ObjectInfo info;
  bool ok = false;  // lowered without errors
  Expr field;       // f(x, a): Expr::x(i), Expr::param(i)
};

// Lowers every object in file order (an object may call the objects before it).
std::vector<LoweredObject> lowerProgram(const Program& program, const CompileOptions& options,
                                        DiagnosticSink& diags);

}  // namespace frep::lang
