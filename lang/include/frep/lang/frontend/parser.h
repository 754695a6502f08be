// Recursive-descent parser for HyperFun (hfp's grammar and precedence; see docs/language.md).
#pragma once

#include <string>
#include <vector>

#include "frep/lang/frontend/ast.h"
#include "frep/lang/frontend/diagnostics.h"
#include "frep/lang/frontend/lexer.h"

namespace frep::lang {

// Parses a whole file. Syntax errors are reported to diags; the parser resynchronises at the
// next ';' (or '}') so that one run reports several errors.
Program parse(const std::vector<Token>& tokens, DiagnosticSink& diags);

}  // namespace frep::lang
