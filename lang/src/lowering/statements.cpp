// Statements: assignments, unrolled while loops, and if on x merged with select().
#include "lowering/object_lowering.h"

namespace frep::lang::detail {

void ObjectLowering::execBlock(const std::vector<Stmt>& stmts) {
  for (const auto& s : stmts) {
    try {
      exec(s);
    } catch (const CompileError& e) {
      error(e.loc, e.message);
      poisonTarget(s);
    }
  }
}

void ObjectLowering::poisonTarget(const Stmt& s) {
  if (s.kind == Stmt::Kind::If || s.kind == Stmt::Kind::While) {
    // A failed condition: what the blocks would have assigned must not cascade into errors.
    for (const auto* block : {&s.body, &s.elseBody})
      for (const auto& inner : *block)
        if (inner.kind != Stmt::Kind::Assign || !env_.count(inner.name)) poisonTarget(inner);
    return;
  }
  auto it = env_.find(s.name);
  if (s.kind == Stmt::Kind::Assign) {
    if (it == env_.end()) {
      Value v;
      v.spelling = s.spelling;
      v.state = Def::Poisoned;
      env_[s.name] = v;
    } else if (!it->second.isArray) {
      it->second.state = Def::Poisoned;
    }
  } else if ((s.kind == Stmt::Kind::AssignElem || s.kind == Stmt::Kind::AssignArray) &&
             it != env_.end() && it->second.isArray) {
    for (auto& st : it->second.elemState)
      if (st != Def::Defined) st = Def::Poisoned;
  }
}

void ObjectLowering::exec(const Stmt& s) {
  switch (s.kind) {
    case Stmt::Kind::Assign: return execAssign(s);
    case Stmt::Kind::AssignElem: return execAssignElem(s);
    case Stmt::Kind::AssignArray: return execAssignArray(s);
    case Stmt::Kind::If: return execIf(s);
    case Stmt::Kind::While: return execWhile(s);
  }
}

Value& ObjectLowering::assignableArray(const Stmt& s) {
  if (s.name == "x" || s.name == "a")
    throw CompileError{s.loc, "cannot assign to '" + s.spelling +
                                  "': x and a are read-only (library transformations may "
                                  "still change them)"};
  auto it = env_.find(s.name);
  if (it == env_.end()) {
    throw CompileError{s.loc, "'" + s.spelling + "' is not a declared array (declare it with "
                                  "'array " + s.spelling + "[n];' at the top of the body)" +
                                  suggestion(s.spelling, false)};
  }
  if (!it->second.isArray)
    throw CompileError{s.loc, "'" + s.spelling + "' is a scalar variable, not an array"};
  if (s.name == "s") attributesWritten_ = true;
  return it->second;
}

void ObjectLowering::checkDepth(const Expr& v, Loc loc) {
  if (v.node().depth > kMaxExprDepth)
    throw CompileError{loc, "expression too deep (more than " + std::to_string(kMaxExprDepth) +
                                " nested operations, e.g. a long unrolled loop)"};
}

void ObjectLowering::execAssign(const Stmt& s) {
  if (s.name == "x" || s.name == "a" || s.name == "s") {
    if (s.name == "s") {
      throw CompileError{s.loc, "'s' is an array; assign an element (s[i] = ...) or a "
                                "literal (s = [...])"};
    }
    assignableArray(s);
  }
  auto it = env_.find(s.name);
  if (it != env_.end() && it->second.isArray)
    throw CompileError{s.loc, "'" + s.spelling + "' is an array; assign an element (" +
                                  s.spelling + "[i] = ...) or a literal (" + s.spelling +
                                  " = [...])"};
  if (it == env_.end()) {
    std::string why = reservedReason(s.name);
    if (!why.empty())
      throw CompileError{s.loc, "cannot assign to '" + s.spelling + "': " + why};
  }
  Expr v = lower(*s.value);
  checkDepth(v, s.loc);
  Value& var = env_[s.name];
  var.spelling = s.spelling;
  var.scalar = v;
  var.state = Def::Defined;
}

void ObjectLowering::execAssignElem(const Stmt& s) {
  Value& arr = assignableArray(s);
  Expr v = lower(*s.value);
  checkDepth(v, s.loc);
  size_t i = constIndex(*s.index, arr);
  arr.elems[i] = v;
  arr.elemState[i] = Def::Defined;
}

void ObjectLowering::execAssignArray(const Stmt& s) {
  Value& arr = assignableArray(s);
  if (s.elems.size() != arr.elems.size())
    throw CompileError{s.loc, "array '" + arr.spelling + "' has " +
                                  plural(arr.elems.size(), "element") +
                                  " but the literal has " + std::to_string(s.elems.size())};
  std::vector<Expr> vals;
  for (const auto& e : s.elems) vals.push_back(lower(*e));
  // Re-find: lowering may have run library calls, but never adds or removes arrays.
  Value& target = env_[s.name];
  target.elems = vals;
  target.elemState.assign(vals.size(), Def::Defined);
}

void ObjectLowering::execIf(const Stmt& s) {
  Expr c = truth(lower(*s.value));
  if (c.isConst()) {
    execBlock(c.constValue() != 0.0 ? s.body : s.elseBody);
    return;
  }
  // Depends on x (or a): run both branches and merge with select().
  Env before = env_;
  execBlock(s.body);
  Env thenEnv = std::move(env_);
  env_ = std::move(before);
  execBlock(s.elseBody);
  Env elseEnv = std::move(env_);
  env_.clear();
  std::set<std::string> keys;
  for (const auto& kv : thenEnv) keys.insert(kv.first);
  for (const auto& kv : elseEnv) keys.insert(kv.first);
  for (const auto& k : keys) {
    auto t = thenEnv.find(k), f = elseEnv.find(k);
    const Value* tv = t == thenEnv.end() ? nullptr : &t->second;
    const Value* fv = f == elseEnv.end() ? nullptr : &f->second;
    env_[k] = merge(c, tv, fv, s.loc);
  }
}

ObjectLowering::Slot ObjectLowering::mergeSlot(const Expr& c, Slot t, Slot f, Loc ifLoc) {
  if (t.state == Def::Poisoned || f.state == Def::Poisoned) return {Def::Poisoned, Expr(), {}};
  if (t.state == Def::Undefined && f.state == Def::Undefined) return {Def::Undefined, Expr(), {}};
  if (t.state == Def::Undefined) return {Def::OneBranch, f.value, ifLoc};
  if (f.state == Def::Undefined) return {Def::OneBranch, t.value, ifLoc};
  Expr v = select(c, t.value, f.value);
  if (t.state == Def::Defined && f.state == Def::Defined) return {Def::Defined, v, {}};
  return {Def::OneBranch, v, t.state == Def::OneBranch ? t.branchIf : f.branchIf};
}

Value ObjectLowering::merge(const Expr& c, const Value* t, const Value* f, Loc ifLoc) {
  Value out = t ? *t : *f;
  if (!out.isArray) {
    Slot ts = t ? Slot{t->state, t->scalar, t->branchIf} : Slot{Def::Undefined, Expr(), {}};
    Slot fs = f ? Slot{f->state, f->scalar, f->branchIf} : Slot{Def::Undefined, Expr(), {}};
    Slot m = mergeSlot(c, ts, fs, ifLoc);
    out.state = m.state;
    out.scalar = m.value;
    out.branchIf = m.branchIf;
    return out;
  }
  for (size_t i = 0; i < out.elems.size(); ++i) {
    Slot ts = t ? Slot{t->elemState[i], t->elems[i], t->branchIf} : Slot{Def::Undefined, Expr(), {}};
    Slot fs = f ? Slot{f->elemState[i], f->elems[i], f->branchIf} : Slot{Def::Undefined, Expr(), {}};
    Slot m = mergeSlot(c, ts, fs, ifLoc);
    out.elemState[i] = m.state;
    out.elems[i] = m.value;
    if (m.state == Def::OneBranch) out.branchIf = m.branchIf;
  }
  return out;
}

void ObjectLowering::execWhile(const Stmt& s) {
  while (true) {
    Expr c = truth(lower(*s.value));
    if (!c.isConst()) {
      bool onX = numVars(c) > 0;
      throw CompileError{s.loc, std::string("the condition of this 'while' depends on ") +
                                    (onX ? "x" : "the parameters a[]") +
                                    "; loops must have a trip count known at compile time " +
                                    (onX ? "(use 'if' for conditions on x)"
                                         : "(give a[] values when compiling, e.g. with -a)")};
    }
    if (c.constValue() == 0.0) return;
    if (++iterations_ > sh_.options.maxLoopIterations) {
      error(s.loc, "loop does not terminate within " +
                       std::to_string(sh_.options.maxLoopIterations) + " iterations");
      throw StopObject{};
    }
    size_t before = errors_;
    execBlock(s.body);
    if (errors_ != before) return;  // the same error would repeat every iteration
  }
}

}  // namespace frep::lang::detail
