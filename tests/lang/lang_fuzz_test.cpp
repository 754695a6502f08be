// Fuzz: thousands of random and mutated model files (fixed seed). Each must compile to either
// a model whose values agree with the tree-walking interpreter, or errors that all carry a
// location; never a crash or a hang (the loop limit bounds every compile).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "frep/lang/frontend/diagnostics.h"
#include "frep/lang/frontend/interpret.h"
#include "frep/lang/frontend/lexer.h"
#include "frep/lang/library/library.h"
#include "lang/lang_test_util.h"

namespace frep::lang::testing {
namespace {

const bool kRegistered = registerAll({
    {"fuzzShift", "AS", "xt[1] -= d (fuzz test)",
     [](std::vector<Arg>& args) {
       auto& xt = *args[0].array;
       if (xt.empty()) throw LibraryError("empty array", 0);
       xt[0] = xt[0] - args[1].value;
       return Expr(1.0);
     }},
});

const char* kSeeds[] = {
    R"(-- blobby sum in HyperFun's sample style
blob(x[3], a[1]) {
  array cx[9], c[3];
  i = 1;
  while i <= 9 loop
    cx[i] = (i - 5) * 0.5;
    i = i + 1;
  endloop;
  s1 = 0; j = 1;
  while (j < 10) loop
    s1 = s1 + exp(-((x[1] - cx[j])^2 + x[2]^2 + x[3]^2));
    j = j + 1;
  endloop;
  blob = s1 - 0.5;
})",
    R"(Box(x[3], a[2]) {
  Box = (a[1] - abs(x[1])) & (a[2] - abs(x[2])) & (1 - abs(x[3]));
}
my_model(x[3], a[1]) {
  array p[2], xt[3];
  p = [1, 2.5];
  xt = [x[1], x[2], x[3]];
  d = fuzzShift(xt, a[1]);
  b = Box(xt, p);
  if x[3] > 0.5 then r = b | sqrt(x[1]^2 + x[2]^2) - 1; else r = b \ (0.25 - x[3]^2); endif;
  my_model = r @ (2 - x[1]);
})",
    R"(twist(x[3], a[1], s[3]) {
  k = 0;
  while k < 4 loop
    if mod(k, 2) = 0 and not (k > 2) then t = sin(k * x[3]); else t = cos(k) * atan2(x[2], x[1]); endif;
    k = k + 1;
  endloop;
  s = [1, 0, 0];
  s[2] = max(t, 0.5);
  twist = -2^2 + 2^3^2 / 64 - logd(1 + x[1]^2) + int(frac(x[2]) * 3) + sign(x[3]) * tanh(x[1]);
})",
};

// Lexes a seed into token texts (mutations work on tokens, then on characters).
std::vector<std::string> tokensOf(const std::string& src) {
  DiagnosticSink sink("seed", src);
  std::vector<std::string> out;
  for (const Token& t : lex(src, sink))
    if (t.kind != Tok::End) out.push_back(t.text);
  return out;
}

std::string join(const std::vector<std::string>& toks, std::mt19937& rng) {
  std::string s;
  for (const auto& t : toks) {
    s += t;
    s += (t == ";" || rng() % 8 == 0) ? "\n" : " ";
  }
  return s;
}

const std::vector<std::string>& vocabulary() {
  static const std::vector<std::string> v = {
      "+", "-", "*", "/", "^", "~", "&", "|", "\\", "@", ",", ";", "=", "(", ")", "[", "]", "{",
      "}", "<", "<=", ">", ">=", "/=", "array", "if", "then", "else", "endif", "while", "loop",
      "endloop", "and", "or", "not", "x", "a", "s", "x[1]", "a[1]", "i", "j", "k", "t", "r", "0",
      "1", "2.5", ".5", "1e3", "9", "-1", "sqrt", "sin", "mod", "max", "fuzzShift", "hfA_SetColor",
      "Box", "blob", "my_model", "twist", "cx", "xt", "p", "--", "\"", "$", "1e999", "0.49999"};
  return v;
}

// Replaces a token by another of the same class (number, operator, function), which mostly
// keeps the model valid and so exercises the lowering on many variants.
bool sameClassEdit(std::vector<std::string>& toks, std::mt19937& rng) {
  static const std::vector<std::vector<std::string>> classes = {
      {"0", "1", "2", "3", "9", "0.5", ".25", "1e3", "2.5", "1.5"},
      {"+", "-", "*", "/", "^", "&", "|", "\\", "@"},
      {"sqrt", "exp", "log", "logd", "sin", "cos", "tan", "asin", "acos", "atan", "abs", "sinh",
       "cosh", "tanh", "sign", "ceil", "floor", "int", "frac"},
      {"<", ">", "<=", ">=", "=", "/="},
      {"and", "or"},
  };
  for (int attempt = 0; attempt < 20; ++attempt) {
    std::string& t = toks[rng() % toks.size()];
    for (const auto& cls : classes)
      if (std::find(cls.begin(), cls.end(), t) != cls.end()) {
        t = cls[rng() % cls.size()];
        return true;
      }
  }
  return false;
}

std::string mutate(const std::string& seed, std::mt19937& rng) {
  std::vector<std::string> toks = tokensOf(seed);
  if (rng() % 3 == 0) {
    int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits; ++e) sameClassEdit(toks, rng);
    return join(toks, rng);
  }
  const auto& vocab = vocabulary();
  // Mostly single edits (which often still compile), sometimes several.
  int tokenEdits = rng() % 2 ? 1 : 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < tokenEdits && !toks.empty(); ++e) {
    size_t i = rng() % toks.size(), j = rng() % toks.size();
    switch (rng() % 4) {
      case 0: toks.erase(toks.begin() + i); break;
      case 1: toks.insert(toks.begin() + i, vocab[rng() % vocab.size()]); break;
      case 2: std::swap(toks[i], toks[j]); break;
      case 3: toks[i] = vocab[rng() % vocab.size()]; break;
    }
  }
  std::string s = join(toks, rng);
  int charEdits = rng() % 3 ? 0 : 1 + static_cast<int>(rng() % 2);
  for (int e = 0; e < charEdits && !s.empty(); ++e) {
    size_t i = rng() % s.size();
    char c = static_cast<char>(rng() % 128);
    switch (rng() % 3) {
      case 0: s.erase(i, 1); break;
      case 1: s.insert(s.begin() + i, c); break;
      case 2: s[i] = c; break;
    }
  }
  return s;
}

std::string randomTokens(std::mt19937& rng) {
  const auto& vocab = vocabulary();
  std::vector<std::string> toks = {"m", "(", "x", "[", "3", "]", ",", "a", "[", "1", "]", ")", "{"};
  size_t n = rng() % 60;
  for (size_t i = 0; i < n; ++i) toks.push_back(vocab[rng() % vocab.size()]);
  if (rng() % 2) toks.push_back("}");
  return join(toks, rng);
}

std::string randomBytes(std::mt19937& rng) {
  std::string s(rng() % 200, ' ');
  for (auto& c : s) c = static_cast<char>(rng() % 256);
  return s;
}

int countLines(const std::string& s) {
  int n = 1;
  for (char c : s) n += c == '\n';
  return n;
}

// Compiled and interpreted values agree: both NaN, equal infinities, or within 1e-9 relative.
void expectSame(double compiled, double interpreted, const std::string& src) {
  if (std::isnan(compiled) || std::isnan(interpreted)) {
    EXPECT_EQ(std::isnan(compiled), std::isnan(interpreted)) << src;
    return;
  }
  if (std::isinf(compiled) || std::isinf(interpreted)) {
    EXPECT_EQ(compiled, interpreted) << src;
    return;
  }
  EXPECT_NEAR(compiled, interpreted, 1e-9 * std::max(1.0, std::fabs(interpreted))) << src;
}

struct Tally {
  int models = 0, errors = 0;
};

void check(const std::string& src, Tally& tally) {
  CompileOptions opt;
  opt.maxLoopIterations = 5000;  // bounds the time of every compile
  CompileResult r = compile(src, "fuzz.hf", opt);
  if (r.ok) {
    ++tally.models;
    ASSERT_GE(r.model.xSize, 1) << src;
    ASSERT_LE(numVars(r.model.field), static_cast<uint32_t>(r.model.xSize)) << src;
    ASSERT_LE(numParams(r.model.field), static_cast<uint32_t>(r.model.aSize)) << src;
    // Any value, NaN included, is a valid answer, but it must be the interpreter's answer.
    Interpreter in(src, opt);
    for (const auto& p : {std::vector<double>{0.3, -0.7, 1.1}, std::vector<double>{-1.9, 0.45, 0.05}}) {
      std::vector<double> x(r.model.xSize);
      for (size_t i = 0; i < x.size(); ++i) x[i] = p[i % 3];
      expectSame(evalModel(r.model, x, {0.5}), in.eval(x, {0.5}), src);
    }
    for (const auto& d : r.diagnostics) ASSERT_NE(d.severity, Diagnostic::Severity::Error);
    return;
  }
  ++tally.errors;
  int lines = countLines(src);
  bool anyError = false;
  for (const auto& d : r.diagnostics) {
    if (d.severity != Diagnostic::Severity::Error) continue;
    anyError = true;
    ASSERT_GE(d.line, 1) << d.format() << "\n--- source:\n" << src;
    ASSERT_LE(d.line, lines) << d.format() << "\n--- source:\n" << src;
    ASSERT_GE(d.column, 1) << d.format();
    ASSERT_FALSE(d.message.empty());
    ASSERT_EQ(d.format().rfind("fuzz.hf:" + std::to_string(d.line) + ":", 0), 0u);
  }
  ASSERT_TRUE(anyError) << "not ok but no error:\n" << src;
}

// FREP_FUZZ_SCALE=k runs k times as many cases (for a long local run; the default is 1).
int scale() {
  const char* s = std::getenv("FREP_FUZZ_SCALE");
  int k = s ? std::atoi(s) : 1;
  return k > 0 ? k : 1;
}

TEST(LangFuzz, SeedsCompile) {
  for (const char* seed : kSeeds) {
    CompileResult r = compile(seed, "seed.hf");
    EXPECT_TRUE(r.ok) << allDiagnostics(r);
  }
}

TEST(LangFuzz, MutatedSeeds) {
  std::mt19937 rng(20261126);
  Tally tally;
  for (int i = 0; i < 4000 * scale(); ++i) {
    std::string src = mutate(kSeeds[i % 3], rng);
    check(src, tally);
    if (::testing::Test::HasFatalFailure()) return;
  }
  std::printf("mutated seeds: %d models, %d rejected with errors\n", tally.models, tally.errors);
  // The mutations must exercise both outcomes, or the test checks little.
  EXPECT_GT(tally.models, 500);
  EXPECT_GT(tally.errors, 1000);
}

TEST(LangFuzz, RandomTokensAndBytes) {
  std::mt19937 rng(7);
  Tally tally;
  for (int i = 0; i < 1500 * scale(); ++i) {
    check(i % 3 == 0 ? randomBytes(rng) : randomTokens(rng), tally);
    if (::testing::Test::HasFatalFailure()) return;
  }
  std::printf("random files: %d models, %d rejected with errors\n", tally.models, tally.errors);
  EXPECT_GT(tally.errors, 1000);
}

TEST(LangFuzz, DeepNestingIsAnErrorNotACrash) {
  std::string open(5000, '('), close(5000, ')');
  CompileResult r = compile("m(x[1], a[1]) { m = " + open + "1" + close + "; }", "deep.hf");
  EXPECT_FALSE(r.ok);
  ASSERT_FALSE(r.diagnostics.empty());
  EXPECT_EQ(r.diagnostics[0].message, "expression nested too deeply");
  std::string chain = "m(x[1], a[1]) { m = 1";
  for (int i = 0; i < 5000; ++i) chain += "+1";
  r = compile(chain + "; }", "chain.hf");
  EXPECT_FALSE(r.ok);
  std::string ifs;
  for (int i = 0; i < 1000; ++i) ifs += "if 1 then ";
  r = compile("m(x[1], a[1]) { " + ifs + " }", "ifs.hf");
  EXPECT_FALSE(r.ok);
}

}  // namespace
}  // namespace frep::lang::testing
