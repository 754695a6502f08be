// Lowering: runs each object's statements symbolically and produces its field as a core Expr.
#pragma once

#include <vector>

#include "frep/expressions/expr.h"
#include "frep/lang/frontend/ast.h"
#include "frep/lang/frontend/diagnostics.h"
#include "frep/lang/hyperfun.h"

namespace frep::lang {

struct LoweredObject {
  ObjectInfo info;
  bool ok = false;  // lowered without errors
  Expr field;       // f(x, a): Expr::x(i), Expr::param(i)
  std::vector<Expr> attributes;  // s[] at the end of the body
  bool attributesWritten = false;
};

// Index of the object compile() selects: options.object, else "my_model", else the first
// (-1 when there is none). Names compare case-insensitively.
int selectedObject(const Program& program, const CompileOptions& options);

// Lowers every object in file order (an object may call the objects before it).
std::vector<LoweredObject> lowerProgram(const Program& program, const CompileOptions& options,
                                        DiagnosticSink& diags, const std::string& modelFile,
                                        std::vector<std::pair<std::string, std::string>>& files);
std::vector<LoweredObject> lowerProgram(const Program& program, const CompileOptions& options,
                                        DiagnosticSink& diags);

}  // namespace frep::lang
