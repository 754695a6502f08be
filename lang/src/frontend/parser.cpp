#include "frep/lang/frontend/parser.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>

namespace frep::lang {
namespace {

// Deep nesting is legal but would exhaust the stack of the recursive parser and lowering.
constexpr int kMaxDepth = 400;
constexpr int kMaxChain = 2000;

struct SyntaxError {
  Loc loc;
  std::string message;
  bool reported = false;  // already reported: only unwind to the statement's recovery point
};

class Parser {
 public:
  Parser(const std::vector<Token>& t, DiagnosticSink& d) : toks_(t), diags_(d) {}

  Program run() {
    Program prog;
    while (!at(Tok::End) && !diags_.full()) {
      if (at(Tok::Ident)) {
        prog.objects.push_back(parseObject());
      } else {
        diags_.error(cur().loc, "expected an object definition 'name(x[n], a[m]) { ... }', found " +
                                    describe(cur()));
        // Skip to just after the next closing brace.
        while (!at(Tok::End) && !at(Tok::RBrace)) next();
        if (at(Tok::RBrace)) next();
      }
    }
    if (prog.objects.empty() && diags_.errorCount() == 0)
      diags_.error(cur().loc, "the file defines no object; expected 'name(x[n], a[m]) { ... }'");
    return prog;
  }

 private:
  // ---- token access -----------------------------------------------------------------------
  const Token& cur() const { return toks_[pos_]; }
  bool at(Tok k) const { return cur().kind == k; }
  const Token& next() {
    const Token& t = toks_[pos_];
    if (pos_ + 1 < toks_.size()) ++pos_;
    return t;
  }
  bool accept(Tok k) {
    if (!at(k)) return false;
    next();
    return true;
  }
  static std::string describe(const Token& t) {
    if (t.kind == Tok::Ident) return "'" + t.text + "'";
    if (t.kind == Tok::Number) return "number " + t.text;
    return tokenName(t.kind);
  }
  [[noreturn]] void fail(const std::string& expected) {
    throw SyntaxError{cur().loc, "expected " + expected + ", found " + describe(cur())};
  }
  const Token& expect(Tok k, const std::string& what = "") {
    if (!at(k)) fail(what.empty() ? tokenName(k) : what);
    return next();
  }
  void report(const SyntaxError& e) {
    if (!e.reported) diags_.error(e.loc, e.message);
  }

  // Skips the rest of a bad statement: through the next ';', or up to a block end.
  void sync() {
    while (!at(Tok::End) && !at(Tok::RBrace) && !at(Tok::KwEndif) && !at(Tok::KwElse) &&
           !at(Tok::KwEndloop)) {
      if (next().kind == Tok::Semi) return;
    }
  }

  // ---- objects ----------------------------------------------------------------------------
  int parseSize(const char* arrayName) {
    expect(Tok::LBracket);
    const Token& t = cur();
    if (t.kind != Tok::Number) fail(std::string("the size of ") + arrayName + "[]");
    // Arrays are unrolled element by element: keep them to a size that compiles quickly.
    if (!(t.number >= 1 && t.number <= 100000 && t.number == std::floor(t.number)))
      throw SyntaxError{t.loc, std::string("the size of ") + arrayName +
                                   "[] must be a whole number from 1 to 100000, not " + t.text};
    next();
    expect(Tok::RBracket);
    return static_cast<int>(t.number);
  }

  void expectArrayName(const char* name) {
    if (!(at(Tok::Ident) && cur().lower == name))
      fail(std::string("'") + name + "' (the header is 'name(x[n], a[m]' with an optional ', s[k]')");
    next();
  }

  void parseHeader(ObjectDecl& obj) {
    expect(Tok::LParen);
    expectArrayName("x");
    obj.xSize = parseSize("x");
    expect(Tok::Comma);
    expectArrayName("a");
    obj.aSize = parseSize("a");
    if (accept(Tok::Comma)) {
      expectArrayName("s");
      obj.sSize = parseSize("s");
    }
    expect(Tok::RParen, "')' closing the object header");
    obj.headerOk = true;
  }

  ObjectDecl parseObject() {
    ObjectDecl obj;
    const Token& nameTok = next();
    obj.name = nameTok.lower;
    obj.spelling = nameTok.text;
    obj.loc = nameTok.loc;
    try {
      parseHeader(obj);
    } catch (const SyntaxError& e) {
      report(e);
      while (!at(Tok::End) && !at(Tok::LBrace) && !at(Tok::RBrace)) next();
    }
    if (!at(Tok::LBrace)) {
      diags_.error(cur().loc, "expected '{' starting the body of object '" + obj.spelling +
                                  "', found " + describe(cur()));
      while (!at(Tok::End) && !at(Tok::RBrace)) next();
      accept(Tok::RBrace);
      obj.headerOk = false;
      return obj;
    }
    next();
    size_t errorsBefore = diags_.errorCount();
    current_ = &obj;
    parseDeclarations(obj);
    obj.body = parseBlock({}, 0);
    current_ = nullptr;
    obj.syntaxErrors = static_cast<int>(diags_.errorCount() - errorsBefore);
    obj.endLoc = cur().loc;
    if (!accept(Tok::RBrace)) {
      diags_.error(cur().loc, "expected '}' closing object '" + obj.spelling + "', found " +
                                  describe(cur()));
    }
    return obj;
  }

  void parseDeclarations(ObjectDecl& obj) {
    while (at(Tok::KwArray)) {
      try {
        next();
        do {
          const Token& n = expect(Tok::Ident, "an array name");
          ArrayDecl d;
          d.name = n.lower;
          d.spelling = n.text;
          d.loc = n.loc;
          d.size = parseSize(n.text.c_str());
          obj.arrays.push_back(d);
        } while (accept(Tok::Comma));
        expect(Tok::Semi);
      } catch (const SyntaxError& e) {
        report(e);
        sync();
      }
    }
  }

  // ---- statements -------------------------------------------------------------------------
  // Parses statements until one of the terminators, '}' or the end of the file.
  std::vector<Stmt> parseBlock(std::initializer_list<Tok> terminators, int depth) {
    std::vector<Stmt> out;
    auto atTerminator = [&] {
      if (at(Tok::End) || at(Tok::RBrace)) return true;
      for (Tok t : terminators)
        if (at(t)) return true;
      return false;
    };
    while (!atTerminator() && !diags_.full()) {
      try {
        if (at(Tok::KwEndif) || at(Tok::KwElse) || at(Tok::KwEndloop)) {
          const char* opener = at(Tok::KwEndloop) ? "while" : "if";
          diags_.error(cur().loc, tokenName(cur().kind) + " without a matching '" + opener + "'");
          next();
          accept(Tok::Semi);
          continue;
        }
        if (at(Tok::KwArray))
          throw SyntaxError{cur().loc, "array declarations must come first in the object body"};
        out.push_back(parseStmt(depth));
      } catch (const SyntaxError& e) {
        report(e);
        if (current_ && !stmtTarget_.empty()) current_->brokenNames.push_back(stmtTarget_);
        size_t before = pos_;
        sync();
        if (pos_ == before && !atTerminator()) next();  // always make progress
      }
    }
    return out;
  }

  Stmt parseStmt(int depth) {
    if (depth > kMaxDepth) throw SyntaxError{cur().loc, "statements nested too deeply"};
    stmtTarget_.clear();
    if (at(Tok::KwIf)) return parseIf(depth);
    if (at(Tok::KwWhile)) return parseWhile(depth);
    Stmt s;
    s.loc = cur().loc;
    stmtTarget_.clear();
    if (!at(Tok::Ident)) fail("a statement");
    const Token& n = next();
    stmtTarget_ = n.lower;
    s.name = n.lower;
    s.spelling = n.text;
    if (accept(Tok::LBracket)) {
      s.kind = Stmt::Kind::AssignElem;
      s.index = parseExpr(0);
      expect(Tok::RBracket);
      expect(Tok::Assign, "'=' in an element assignment");
      s.value = parseExpr(0);
    } else {
      expect(Tok::Assign, "'=' after '" + n.text + "'");
      if (accept(Tok::LBracket)) {
        s.kind = Stmt::Kind::AssignArray;
        do s.elems.push_back(parseExpr(0));
        while (accept(Tok::Comma));
        expect(Tok::RBracket, "']' closing the array literal");
      } else {
        s.kind = Stmt::Kind::Assign;
        s.value = parseExpr(0);
      }
    }
    if (!at(Tok::Semi)) {
      if (at(Tok::Lt) || at(Tok::Gt) || at(Tok::Le) || at(Tok::Ge) || at(Tok::Ne) ||
          at(Tok::Assign) || at(Tok::KwAnd) || at(Tok::KwOr))
        throw SyntaxError{cur().loc, "expected ';', found " + describe(cur()) +
                                         " (comparisons belong in 'if'/'while' conditions or in "
                                         "parentheses)"};
      fail("';'");
    }
    next();
    return s;
  }

  // Parses a condition; on error reports it and skips to the keyword that follows it.
  AstExprPtr parseCondRecovering(Tok until) {
    try {
      AstExprPtr c = parseCond(0);
      if (!at(until)) fail(tokenName(until));
      return c;
    } catch (const SyntaxError& e) {
      report(e);
      while (!at(Tok::End) && !at(until) && !at(Tok::Semi) && !at(Tok::RBrace)) next();
      if (!at(until)) throw SyntaxError{e.loc, e.message, true};
      auto n = std::make_unique<AstExpr>();  // stands in for the bad condition
      n->loc = cur().loc;
      return n;
    }
  }

  Stmt parseIf(int depth) {
    Stmt s;
    s.kind = Stmt::Kind::If;
    s.loc = next().loc;
    s.value = parseCondRecovering(Tok::KwThen);
    expect(Tok::KwThen);
    s.body = parseBlock({Tok::KwElse, Tok::KwEndif, Tok::KwEndloop}, depth + 1);
    if (accept(Tok::KwElse)) s.elseBody = parseBlock({Tok::KwEndif, Tok::KwElse, Tok::KwEndloop}, depth + 1);
    closeBlock(Tok::KwEndif, "if", s.loc);
    return s;
  }

  Stmt parseWhile(int depth) {
    Stmt s;
    s.kind = Stmt::Kind::While;
    s.loc = next().loc;
    s.value = parseCondRecovering(Tok::KwLoop);
    expect(Tok::KwLoop);
    s.body = parseBlock({Tok::KwEndloop, Tok::KwElse, Tok::KwEndif}, depth + 1);
    closeBlock(Tok::KwEndloop, "while", s.loc);
    return s;
  }

  // Expects "endif;" or "endloop;". The wrong closer (endloop for an if, a second else) is
  // reported and consumed as if it were the right one, so the statement still ends here.
  void closeBlock(Tok closer, const char* opener, Loc openLoc) {
    std::string what = tokenName(closer) + " closing the '" + opener + "' at line " +
                       std::to_string(openLoc.line);
    if (!at(closer)) {
      if (!(at(Tok::KwEndif) || at(Tok::KwEndloop) || at(Tok::KwElse))) fail(what);
      diags_.error(cur().loc, "expected " + what + ", found " + describe(cur()));
      next();
    } else {
      next();
    }
    expect(Tok::Semi, "';' after " + tokenName(closer));
  }

  // ---- expressions ------------------------------------------------------------------------
  static AstExprPtr node(AstExpr::Kind k, Loc loc) {
    auto n = std::make_unique<AstExpr>();
    n->kind = k;
    n->loc = loc;
    return n;
  }
  void checkDepth(int depth) {
    if (depth > kMaxDepth) throw SyntaxError{cur().loc, "expression nested too deeply"};
  }
  // Left-deep operator chains grow the tree without recursing in the parser; bound them so
  // the recursive lowering stays within the stack.
  AstExprPtr chain(AstExprPtr l, AstExprPtr n, AstExprPtr r, int& length) {
    if (++length > kMaxChain)
      throw SyntaxError{n->loc, "expression too long (more than " +
                                    std::to_string(kMaxChain) + " operators in a chain)"};
    n->args.push_back(std::move(l));
    n->args.push_back(std::move(r));
    return n;
  }

  // cond := cmp {('and'|'or') cmp}
  AstExprPtr parseCond(int depth) {
    checkDepth(depth);
    AstExprPtr l = parseCmp(depth);
    int length = 0;
    while (at(Tok::KwAnd) || at(Tok::KwOr)) {
      AstExpr::Kind kind = at(Tok::KwAnd) ? AstExpr::Kind::And : AstExpr::Kind::Or;
      auto n = node(kind, next().loc);
      l = chain(std::move(l), std::move(n), parseCmp(depth), length);
    }
    return l;
  }

  // cmp := cterm {relop cterm}
  AstExprPtr parseCmp(int depth) {
    AstExprPtr l = parseCTerm(depth);
    int length = 0;
    while (true) {
      RelOp op;
      switch (cur().kind) {
        case Tok::Assign: op = RelOp::Eq; break;
        case Tok::Ne: op = RelOp::Ne; break;
        case Tok::Lt: op = RelOp::Lt; break;
        case Tok::Gt: op = RelOp::Gt; break;
        case Tok::Le: op = RelOp::Le; break;
        case Tok::Ge: op = RelOp::Ge; break;
        default: return l;
      }
      auto n = node(AstExpr::Kind::Compare, next().loc);
      n->relop = op;
      l = chain(std::move(l), std::move(n), parseCTerm(depth), length);
    }
  }

  // cterm := 'not' cterm | expr      (hfp: "not a < b" is "(not a) < b")
  AstExprPtr parseCTerm(int depth) {
    if (at(Tok::KwNot)) {
      checkDepth(depth + 1);
      auto n = node(AstExpr::Kind::Not, next().loc);
      n->args.push_back(parseCTerm(depth + 1));
      return n;
    }
    return parseExpr(depth);
  }

  // expr := term {('+'|'-'|'|'|'&'|'\'|'@') term}   -- one level, as hfp
  AstExprPtr parseExpr(int depth) {
    checkDepth(depth);
    AstExprPtr l = parseTerm(depth);
    int length = 0;
    while (true) {
      BinOp op;
      switch (cur().kind) {
        case Tok::Plus: op = BinOp::Add; break;
        case Tok::Minus: op = BinOp::Sub; break;
        case Tok::Bar: op = BinOp::Union; break;
        case Tok::Amp: op = BinOp::Inter; break;
        case Tok::Backslash: op = BinOp::Diff; break;
        case Tok::At: op = BinOp::Cart; break;
        default: return l;
      }
      auto n = node(AstExpr::Kind::Binary, next().loc);
      n->binop = op;
      l = chain(std::move(l), std::move(n), parseTerm(depth), length);
    }
  }

  AstExprPtr parseTerm(int depth) {
    AstExprPtr l = parsePow(depth);
    int length = 0;
    while (at(Tok::Star) || at(Tok::Slash)) {
      auto n = node(AstExpr::Kind::Binary, cur().loc);
      n->binop = next().kind == Tok::Star ? BinOp::Mul : BinOp::Div;
      l = chain(std::move(l), std::move(n), parsePow(depth), length);
    }
    return l;
  }

  // pow := unary {'^' unary}   -- left associative: 2^3^2 = 64
  AstExprPtr parsePow(int depth) {
    AstExprPtr l = parseUnary(depth);
    int length = 0;
    while (at(Tok::Caret)) {
      auto n = node(AstExpr::Kind::Binary, next().loc);
      n->binop = BinOp::Pow;
      l = chain(std::move(l), std::move(n), parseUnary(depth), length);
    }
    return l;
  }

  // unary := ('+'|'-'|'~') unary | primary   -- tighter than '^': -2^2 = 4
  AstExprPtr parseUnary(int depth) {
    if (at(Tok::Minus) || at(Tok::Plus) || at(Tok::Tilde)) {
      checkDepth(depth + 1);
      auto n = node(AstExpr::Kind::Unary, cur().loc);
      Tok k = next().kind;
      n->unop = k == Tok::Minus ? UnOp::Neg : k == Tok::Plus ? UnOp::Plus : UnOp::Complement;
      n->args.push_back(parseUnary(depth + 1));
      return n;
    }
    return parsePrimary(depth);
  }

  AstExprPtr parsePrimary(int depth) {
    const Token& t = cur();
    if (t.kind == Tok::Number) {
      auto n = node(AstExpr::Kind::Number, t.loc);
      n->number = t.number;
      next();
      return n;
    }
    if (t.kind == Tok::String) {
      auto n = node(AstExpr::Kind::String, t.loc);
      n->name = n->spelling = t.text;
      next();
      return n;
    }
    if (t.kind == Tok::LParen) {
      next();
      // A parenthesised condition is allowed anywhere (hfp allows it only in conditions).
      AstExprPtr inner = parseCond(depth + 1);
      expect(Tok::RParen, "')'");
      return inner;
    }
    if (t.kind == Tok::Ident) {
      next();
      auto n = node(AstExpr::Kind::Name, t.loc);
      n->name = t.lower;
      n->spelling = t.text;
      if (accept(Tok::LBracket)) {
        n->kind = AstExpr::Kind::Index;
        n->args.push_back(parseExpr(depth + 1));
        expect(Tok::RBracket, "']'");
      } else if (accept(Tok::LParen)) {
        n->kind = AstExpr::Kind::Call;
        if (!at(Tok::RParen)) {
          do n->args.push_back(parseExpr(depth + 1));
          while (accept(Tok::Comma));
        }
        expect(Tok::RParen, "')' or ',' in the call of '" + t.text + "'");
      }
      return n;
    }
    fail("an expression");
  }

  const std::vector<Token>& toks_;
  DiagnosticSink& diags_;
  size_t pos_ = 0;
  ObjectDecl* current_ = nullptr;  // the object whose body is being parsed
  std::string stmtTarget_;         // the variable the current statement assigns
};

}  // namespace

Program parse(const std::vector<Token>& tokens, DiagnosticSink& diags) {
  return Parser(tokens, diags).run();
}

}  // namespace frep::lang
