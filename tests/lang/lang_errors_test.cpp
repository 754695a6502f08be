// Every kind of syntax and semantic error: its message at the exact line and column.
#include "frep/lang/frontend/diagnostics.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

struct ErrorCase {
  const char* name;
  const char* source;
  int line, column;
  const char* message;
};

// Wraps a body into a 3D object on lines 1..n; the body starts on line 2.
std::string obj(const std::string& body) { return "m(x[3], a[1])\n{\n" + body + "\n}\n"; }

const ErrorCase kCases[] = {
    // lexical
    {"BadCharacter", "m(x[3], a[1]) {\n  m = 1 $ 2;\n}", 2, 9, "unexpected character '$'"},
    {"MalformedNumber", "m(x[3], a[1]) {\n  m = 2e;\n}", 2, 7, "malformed number '2e'"},
    {"NumberOutOfRange", "m(x[3], a[1]) {\n  m = 1e999;\n}", 2, 7, "number '1e999' is out of range"},
    {"BangEquals", "m(x[3], a[1]) {\n  if x[1] != 0 then m = 1; endif;\n}", 2, 11,
     "unexpected '!='; HyperFun writes 'not equal' as '/='"},
    {"StringLiteral", "m(x[3], a[1]) {\n  m = \"s\";\n}", 2, 7,
     "a string is only allowed as a file name argument (frVolumeSplineFile, frMesh, frVolume) or a grid name (frVolume)"},
    {"UnterminatedString", "m(x[3], a[1]) {\n  m = \"s;\n}", 2, 7,
     "unterminated string (a string ends with '\"' on the same line)"},
    // syntax
    {"EmptyFile", "  \n", 2, 1, "the file defines no object; expected 'name(x[n], a[m]) { ... }'"},
    {"NotAnObject", "42", 1, 1,
     "expected an object definition 'name(x[n], a[m]) { ... }', found number 42"},
    {"HeaderMissingComma", "m(x[3] a[1]) { m = 1; }", 1, 8, "expected ',', found 'a'"},
    {"HeaderWrongArray", "m(y[3], a[1]) { m = 1; }", 1, 3,
     "expected 'x' (the header is 'name(x[n], a[m]' with an optional ', s[k]'), found 'y'"},
    {"HeaderZeroSize", "m(x[0], a[1]) { m = 1; }", 1, 5,
     "the size of x[] must be a whole number from 1 to 100000, not 0"},
    {"MissingBrace", "m(x[3], a[1]) m = 1; }", 1, 15,
     "expected '{' starting the body of object 'm', found 'm'"},
    {"UnclosedBody", "m(x[3], a[1]) {\n  m = 1;\n", 3, 1,
     "expected '}' closing object 'm', found end of file"},
    {"MissingSemicolon", "m(x[3], a[1]) {\n  r = 2\n  m = r;\n}", 3, 3, "expected ';', found 'm'"},
    {"MissingOperand", "m(x[3], a[1]) {\n  m = x[1] + ;\n}", 2, 14, "expected an expression, found ';'"},
    {"UnclosedParen", "m(x[3], a[1]) {\n  m = (x[1] + 1;\n}", 2, 16, "expected ')', found ';'"},
    {"UnclosedIndex", "m(x[3], a[1]) {\n  m = x[1;\n}", 2, 10, "expected ']', found ';'"},
    {"ComparisonAsValue", "m(x[3], a[1]) {\n  m = x[1] < 2;\n}", 2, 12,
     "expected ';', found '<' (comparisons belong in 'if'/'while' conditions or in parentheses)"},
    {"MissingThen", "m(x[3], a[1]) {\n  m = 1;\n  if x[1] > 0 m = 2; endif;\n}", 3, 15,
     "expected 'then', found 'm'"},
    {"WrongCloser", "m(x[3], a[1]) {\n  m = 1;\n  if 1 then m = 2; endloop;\n}", 3, 20,
     "expected 'endif' closing the 'if' at line 3, found 'endloop'"},
    {"StrayEndif", "m(x[3], a[1]) {\n  m = 1;\n  endif;\n}", 3, 3, "'endif' without a matching 'if'"},
    {"MissingEndloop", "m(x[3], a[1]) {\n  m = 1;\n  while 0 loop m = 2;\n}", 4, 1,
     "expected 'endloop' closing the 'while' at line 3, found '}'"},
    {"LateDeclaration", "m(x[3], a[1]) {\n  m = 1;\n  array v[2];\n}", 3, 3,
     "array declarations must come first in the object body"},
    {"StatementStartsWithNumber", "m(x[3], a[1]) {\n  3 = m;\n  m = 1;\n}", 2, 3,
     "expected a statement, found number 3"},
    // semantic: names
    {"UnknownName", "m(x[3], a[1]) {\n  radius = 1;\n  m = radus - x[1];\n}", 3, 7,
     "unknown name 'radus'; did you mean 'radius'?"},
    {"UnknownFunction", "m(x[3], a[1]) {\n  m = sqr(x[1]);\n}", 2, 7,
     "unknown function 'sqr'; did you mean 'sqrt'?"},
    {"UnknownObjectSuggestion", "Box(x[3], a[1]) { Box = 1; }\nm(x[3], a[1]) {\n  m = Bx(x, a);\n}",
     3, 7, "unknown function 'Bx'; did you mean 'box'?"},
    {"UsedBeforeAssigned", "m(x[3], a[1]) {\n  m = r;\n  r = 1;\n}", 2, 7,
     "'r' is used before it is assigned"},
    {"ArrayAsScalar", "m(x[3], a[1]) {\n  m = x;\n}", 2, 7, "'x' is an array; use an element, e.g. x[1]"},
    {"FunctionAsValue", "m(x[3], a[1]) {\n  m = sin;\n}", 2, 7, "'sin' is a function; call it as sin(...)"},
    {"ScalarIndexed", "m(x[3], a[1]) {\n  r = 1;\n  m = r[1];\n}", 3, 7,
     "'r' is a scalar variable, not an array"},
    {"VariableCalled", "m(x[3], a[1]) {\n  r = 1;\n  m = r(1);\n}", 3, 7, "'r' is a variable, not a function"},
    {"AssignToX", "m(x[3], a[1]) {\n  x[1] = 2;\n  m = 1;\n}", 2, 3,
     "cannot assign to 'x': x and a are read-only (library transformations may still change them)"},
    {"AssignToBuiltin", "m(x[3], a[1]) {\n  sin = 2;\n  m = 1;\n}", 2, 3,
     "cannot assign to 'sin': it is a builtin function"},
    {"AssignScalarToArray", "m(x[3], a[1]) {\n  array v[2];\n  v = 1;\n  m = 1;\n}", 3, 3,
     "'v' is an array; assign an element (v[i] = ...) or a literal (v = [...])"},
    {"UndeclaredArrayElement", "m(x[3], a[1]) {\n  w[1] = 1;\n  m = 1;\n}", 2, 3,
     "'w' is not a declared array (declare it with 'array w[n];' at the top of the body)"},
    {"DuplicateArray", "m(x[3], a[1]) {\n  array v[2], v[3];\n  m = 1;\n}", 2, 15,
     "array 'v' is already declared"},
    {"ArrayNamedLikeBuiltin", "m(x[3], a[1]) {\n  array exp[2];\n  m = 1;\n}", 2, 9,
     "cannot declare an array named 'exp': it is a builtin function"},
    // semantic: arrays and indices
    {"IndexOutOfRange", "m(x[3], a[1]) {\n  m = x[4];\n}", 2, 9,
     "index 4 is out of range for 'x' (elements 1 to 3)"},
    {"IndexRoundsOutOfRange", "m(x[3], a[1]) {\n  m = x[0.4];\n}", 2, 9,
     "index 0.4 is out of range for 'x' (elements 1 to 3)"},
    // Reads at an x-dependent index compile (a select chain); assignments do not.
    {"IndexOnX", "m(x[3], a[1]) {\n  array v[2];\n  v[x[1]] = 1;\n  m = 1;\n}", 3, 5,
     "array index must be known at compile time; this one depends on x"},
    {"IndexOnParameter", "m(x[3], a[1]) {\n  array v[2];\n  v[a[1]] = 1;\n  m = 1;\n}", 3, 5,
     "array index must be known at compile time; this one depends on the parameters a[]"},
    {"VaryingIndexUnassigned", "m(x[3], a[1]) {\n  array v[2];\n  v[1] = 1;\n  m = v[x[1]];\n}", 4, 7,
     "element v[2] is not assigned, and this index depends on x, so it may read any element: "
     "assign them all first"},
    {"LiteralSize", "m(x[3], a[1]) {\n  array v[2];\n  v = [1, 2, 3];\n  m = 1;\n}", 3, 3,
     "array 'v' has 2 elements but the literal has 3"},
    {"UnassignedElement", "m(x[3], a[1]) {\n  array v[2];\n  m = v[2];\n}", 3, 7,
     "element v[2] is read before it is assigned"},
    // semantic: calls
    {"BuiltinArity", "m(x[3], a[1]) {\n  m = atan2(x[1]);\n}", 2, 7, "'atan2' takes 2 arguments, not 1"},
    {"ObjectCallsLater", "m(x[3], a[1]) {\n  m = later(x, a);\n}\nlater(x[3], a[1]) { later = 1; }",
     2, 7, "object 'later' is defined later (line 4); an object can only call objects defined before it"},
    {"ObjectCallsItself", "m(x[3], a[1]) {\n  m = m(x, a);\n}", 2, 7, "object 'm' cannot call itself"},
    {"ObjectCallSize", "b(x[2], a[1]) { b = 1; }\nm(x[3], a[1]) {\n  m = b(x, a);\n}", 3, 9,
     "object 'b' expects x[2], but 'x' has 3 elements"},
    {"ObjectCallArgCount", "b(x[3], a[1]) { b = 1; }\nm(x[3], a[1]) {\n  m = b(x);\n}", 3, 7,
     "object 'b' is called with its arrays: b(x, a) or b(x, a, s), not with 1 argument"},
    {"ObjectCallNotArray", "b(x[3], a[1]) { b = 1; }\nm(x[3], a[1]) {\n  m = b(x, 2);\n}", 3, 12,
     "argument 2 of object 'b' must be an array name (x, a, s or a declared array)"},
    {"DuplicateObject", "m(x[3], a[1]) { m = 1; }\nm(x[3], a[1]) { m = 2; }", 2, 1,
     "object 'm' is already defined at line 1"},
    {"ObjectNamedLikeBuiltin", "sin(x[3], a[1]) { sin = 1; }", 1, 1,
     "an object cannot be named 'sin': it is a builtin function"},
    // semantic: control flow
    {"NeverAssigned", "m(x[3], a[1]) {\n  r = 1;\n}", 3, 1,
     "object 'm' never assigns its value; end the body with 'm = expression;'"},
    {"OneBranchOnly", "m(x[3], a[1]) {\n  if x[1] > 0 then t = 1; endif;\n  m = t;\n}", 3, 7,
     "'t' may be unassigned here: it is assigned in only one branch of the 'if' at 2:3, whose "
     "condition depends on x (assign it before the 'if' or in both branches)"},
    {"WhileOnX", "m(x[3], a[1]) {\n  m = 0;\n  while x[1] > m loop m = m + 1; endloop;\n}", 3, 3,
     "the condition of this 'while' depends on x; loops must have a trip count known at compile "
     "time (use 'if' for conditions on x)"},
    {"WhileOnParameter", "m(x[3], a[1]) {\n  m = 0;\n  while m < a[1] loop m = m + 1; endloop;\n}", 3, 3,
     "the condition of this 'while' depends on the parameters a[]; loops must have a trip count "
     "known at compile time (give a[] values when compiling, e.g. with -a)"},
    {"EndlessLoop", "m(x[3], a[1]) {\n  i = 0;\n  while i < 1 loop m = 1; endloop;\n}", 3, 3,
     "loop does not terminate within 1000000 iterations"},
};

class LangErrors : public ::testing::TestWithParam<ErrorCase> {};

TEST_P(LangErrors, ReportsMessageAtPlace) {
  const ErrorCase& c = GetParam();
  CompileResult r = compile(c.source, "err.hf");
  EXPECT_FALSE(r.ok);
  ASSERT_FALSE(r.diagnostics.empty());
  const Diagnostic& d = r.diagnostics.front();
  EXPECT_EQ(d.severity, Diagnostic::Severity::Error);
  EXPECT_EQ(d.file, "err.hf");
  EXPECT_EQ(d.message, c.message) << allDiagnostics(r);
  EXPECT_EQ(d.line, c.line) << allDiagnostics(r);
  EXPECT_EQ(d.column, c.column) << allDiagnostics(r);
}

INSTANTIATE_TEST_SUITE_P(AllKinds, LangErrors, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<ErrorCase>& info) {
                           return std::string(info.param.name);
                         });

TEST(LangDiagnostics, FormatShowsLineAndCaret) {
  CompileResult r = compile("m(x[3], a[1]) {\n\tm = sqr(x[1]);\n}\n", "dir/model.hf");
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].format(),
            "dir/model.hf:2:6: error: unknown function 'sqr'; did you mean 'sqrt'?\n"
            "  \tm = sqr(x[1]);\n"
            "  \t    ^");
}

TEST(LangDiagnostics, WarningFormat) {
  Diagnostic d;
  d.severity = Diagnostic::Severity::Warning;
  d.file = "f.hf";
  d.line = 1;
  d.column = 3;
  d.message = "careful";
  d.sourceLine = "abcdef";
  EXPECT_EQ(d.format(), "f.hf:1:3: warning: careful\n  abcdef\n    ^");
  d.line = 0;
  EXPECT_EQ(d.format(), "f.hf: warning: careful");
}

TEST(LangDiagnostics, RecoversToReportSeveralErrors) {
  CompileResult r = compile(
      "m(x[3], a[1]) {\n"
      "  r = 2 2;\n"           // syntax error, line 2
      "  q = (1 + ;\n"         // syntax error, line 3
      "  m = r + zz;\n"        // unknown name, line 4 (r is not reported again)
      "  if x[1] > 0 then t = 1; endif;\n"
      "  m = m + t;\n"         // one-branch error, line 6
      "}\n"
      "n(x[3], a[1]) { n = sqr(1); }\n",  // second object still checked, line 8
      "many.hf");
  EXPECT_FALSE(r.ok);
  ASSERT_EQ(r.diagnostics.size(), 5u) << allDiagnostics(r);
  int lines[] = {2, 3, 4, 6, 8};
  for (int i = 0; i < 5; ++i) EXPECT_EQ(r.diagnostics[i].line, lines[i]) << allDiagnostics(r);
  EXPECT_EQ(r.diagnostics[2].message, "unknown name 'zz'");
}

// The error limit may be reached while the arrays are declared, before any statement runs
// (a fuzzer's find: the stop escaped and aborted the process).
TEST(LangDiagnostics, ErrorLimitInArrayDeclarationsStopsCleanly) {
  std::string decls = "  array v[1]";
  for (int i = 0; i < 150; ++i) decls += ", v[1]";
  CompileResult r = compile("m(x[3], a[1]) {\n" + decls + ";\n  m = 1;\n}\n", "arrays.hf");
  EXPECT_FALSE(r.ok);
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_LE(r.diagnostics.size(), DiagnosticSink::kMaxErrors + 1) << allDiagnostics(r);
  EXPECT_EQ(r.diagnostics[0].message, "array 'v' is already declared");
}

TEST(LangDiagnostics, FailedConditionDoesNotCascade) {
  CompileResult r = compile(obj("if qq > 0 then t = 1; else t = 2; endif;\nm = t;"), "c.hf");
  ASSERT_EQ(r.diagnostics.size(), 1u) << allDiagnostics(r);
  EXPECT_EQ(r.diagnostics[0].message, "unknown name 'qq'");
}

TEST(LangDiagnostics, ErrorInLoopReportedOnce) {
  CompileResult r = compile(obj("i = 0;\nwhile i < 5 loop\n  m = q;\n  i = i + 1;\nendloop;"),
                            "loop.hf");
  ASSERT_EQ(r.diagnostics.size(), 1u) << allDiagnostics(r);
  EXPECT_EQ(r.diagnostics[0].line, 5);
}

TEST(LangDiagnostics, LoopLimitIsConfigurable) {
  CompileOptions opt;
  opt.maxLoopIterations = 10;
  std::string src = obj("i = 0;\nwhile i < 10 loop i = i + 1; endloop;\nm = i;");
  CompileResult ok = compile(src, "lim.hf", opt);
  EXPECT_TRUE(ok.ok) << allDiagnostics(ok);
  opt.maxLoopIterations = 9;
  CompileResult bad = compile(src, "lim.hf", opt);
  EXPECT_FALSE(bad.ok);
  ASSERT_EQ(bad.diagnostics.size(), 1u);
  EXPECT_EQ(bad.diagnostics[0].message, "loop does not terminate within 9 iterations");
  EXPECT_EQ(bad.diagnostics[0].line, 4);
  EXPECT_EQ(bad.diagnostics[0].column, 1);
}

TEST(LangDiagnostics, TooDeepExpressionIsAnError) {
  CompileResult r = compile(obj("i = 0; s1 = 0;\nwhile i < 20000 loop s1 = s1 + x[1]; i = i + 1; endloop;\nm = s1;"),
                            "deep.hf");
  EXPECT_FALSE(r.ok);
  ASSERT_EQ(r.diagnostics.size(), 1u);
  EXPECT_EQ(r.diagnostics[0].line, 4);
  EXPECT_EQ(r.diagnostics[0].column, 22);
}

TEST(LangDiagnostics, ClosestName) {
  EXPECT_EQ(closestName("radus", {"radius", "r", "sqrt"}), "radius");
  EXPECT_EQ(closestName("HFSPHER", {"hfSphere", "hfTorusX"}), "hfSphere");
  EXPECT_EQ(closestName("q", {"a", "x"}), "");  // one-letter names: no guess
  EXPECT_EQ(closestName("completely", {"sqrt", "exp"}), "");
  EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
}

}  // namespace
}  // namespace frep::lang::testing
