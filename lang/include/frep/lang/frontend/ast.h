// Syntax tree of a HyperFun file, as the parser builds it and the lowering consumes it.
// Names are kept twice: lower-cased (HyperFun compares names case-insensitively) and as written
// (for messages).
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace frep::lang {

struct Loc {
  int line = 0, column = 0;  // 1-based
};

enum class BinOp { Add, Sub, Union, Inter, Diff, Cart, Mul, Div, Pow };
enum class UnOp { Neg, Plus, Complement };
enum class RelOp { Eq, Ne, Lt, Gt, Le, Ge };

struct AstExpr;
using AstExprPtr = std::unique_ptr<AstExpr>;

struct AstExpr {
  enum class Kind { Number, Name, Index, Call, Unary, Binary, Compare, And, Or, Not, String };
  Kind kind = Kind::Number;
  Loc loc;                    // operator or first token
  double number = 0.0;        // Number
  std::string name;           // Name, Index, Call: lower-cased; String: its text
  std::string spelling;       // as written
  UnOp unop = UnOp::Neg;
  BinOp binop = BinOp::Add;
  RelOp relop = RelOp::Eq;
  std::vector<AstExprPtr> args;  // operands, call arguments, or the index
};

struct Stmt {
  enum class Kind { Assign, AssignElem, AssignArray, If, While };
  Kind kind = Kind::Assign;
  Loc loc;                 // first token of the statement
  std::string name, spelling;  // assigned variable / array
  AstExprPtr index;        // AssignElem
  AstExprPtr value;        // Assign, AssignElem; condition of If/While
  std::vector<AstExprPtr> elems;  // AssignArray
  std::vector<Stmt> body, elseBody;
};

struct ArrayDecl {
  std::string name, spelling;
  int size = 0;
  Loc loc;
};

struct ObjectDecl {
  std::string name, spelling;
  Loc loc;
  int xSize = 0, aSize = 0, sSize = 0;  // sSize 0: no s[] in the header
  std::vector<ArrayDecl> arrays;
  std::vector<Stmt> body;
  Loc endLoc;           // the closing brace
  bool headerOk = false;  // header parsed well enough to lower the body
  int syntaxErrors = 0;   // in the body; the lowering then skips follow-on errors
  std::vector<std::string> brokenNames;  // targets of statements that failed to parse
};

struct Program {
  std::vector<ObjectDecl> objects;
};

}  // namespace frep::lang
