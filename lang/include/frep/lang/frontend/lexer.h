// Tokens of the HyperFun language.
#pragma once

#include <string>
#include <vector>

#include "frep/lang/frontend/ast.h"
#include "frep/lang/frontend/diagnostics.h"

namespace frep::lang {

enum class Tok {
  End, Number, Ident, String /* "...": a file name argument */,
  Plus, Minus, Star, Slash, Caret, Tilde, Amp, Bar, Backslash, At,
  Comma, Semi, Assign /* '=' (assignment and equality) */, LParen, RParen, LBracket, RBracket,
  LBrace, RBrace, Lt, Le, Gt, Ge, Ne,
  KwArray, KwIf, KwThen, KwElse, KwEndif, KwWhile, KwLoop, KwEndloop, KwAnd, KwOr, KwNot,
};

struct Token {
  Tok kind = Tok::End;
  std::string text;   // as written
  std::string lower;  // lower-cased (identifiers, keywords)
  double number = 0.0;
  Loc loc;
};

// How a token kind reads in messages, e.g. "';'" or "'endif'".
std::string tokenName(Tok kind);

// Splits source into tokens ending with Tok::End. Comments run from "--" to the end of the line;
// space, tab, CR and LF separate tokens. Bad characters are reported and skipped.
std::vector<Token> lex(const std::string& source, DiagnosticSink& diags);

}  // namespace frep::lang
