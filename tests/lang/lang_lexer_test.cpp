// Tokens, numbers, comments, line/column tracking.
#include <gtest/gtest.h>

#include "frep/lang/frontend/lexer.h"

namespace frep::lang {
namespace {

std::vector<Token> lexOk(const std::string& src) {
  DiagnosticSink sink("t.hf", src);
  auto toks = lex(src, sink);
  EXPECT_EQ(sink.errorCount(), 0u);
  return toks;
}

TEST(LangLexer, OperatorsAndKeywords) {
  auto t = lexOk("^ + - ~ * / & | \\ @ , ; = ( ) [ ] { } < <= > >= /= "
                 "ARRAY If then Else endif WHILE loop endloop and Or not");
  std::vector<Tok> want = {
      Tok::Caret, Tok::Plus, Tok::Minus, Tok::Tilde, Tok::Star, Tok::Slash, Tok::Amp, Tok::Bar,
      Tok::Backslash, Tok::At, Tok::Comma, Tok::Semi, Tok::Assign, Tok::LParen, Tok::RParen,
      Tok::LBracket, Tok::RBracket, Tok::LBrace, Tok::RBrace, Tok::Lt, Tok::Le, Tok::Gt, Tok::Ge,
      Tok::Ne, Tok::KwArray, Tok::KwIf, Tok::KwThen, Tok::KwElse, Tok::KwEndif, Tok::KwWhile,
      Tok::KwLoop, Tok::KwEndloop, Tok::KwAnd, Tok::KwOr, Tok::KwNot, Tok::End};
  ASSERT_EQ(t.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(t[i].kind, want[i]) << i;
}

TEST(LangLexer, NumbersInAllForms) {
  auto t = lexOk("12 1.5 .5 2e3 2E-2 1.e1 3.25e+1 007");
  double want[] = {12, 1.5, 0.5, 2000, 0.02, 10, 32.5, 7};
  ASSERT_EQ(t.size(), 9u);
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(t[i].kind, Tok::Number);
    EXPECT_DOUBLE_EQ(t[i].number, want[i]);
  }
}

TEST(LangLexer, IdentifiersKeepSpellingAndLowerCase) {
  auto t = lexOk("My_Model hfSphere x_2");
  EXPECT_EQ(t[0].text, "My_Model");
  EXPECT_EQ(t[0].lower, "my_model");
  EXPECT_EQ(t[1].lower, "hfsphere");
  EXPECT_EQ(t[2].kind, Tok::Ident);
}

TEST(LangLexer, CommentsAndLocations) {
  auto t = lexOk("a--1 comment\r\n\t b -- more\n  c");
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[0].loc.line, 1);
  EXPECT_EQ(t[0].loc.column, 1);
  EXPECT_EQ(t[1].text, "b");
  EXPECT_EQ(t[1].loc.line, 2);
  EXPECT_EQ(t[1].loc.column, 3);  // tab and space are one column each
  EXPECT_EQ(t[2].loc.line, 3);
  EXPECT_EQ(t[2].loc.column, 3);
  EXPECT_EQ(t[3].kind, Tok::End);
}

TEST(LangLexer, BadCharactersAreReportedAndSkipped) {
  DiagnosticSink sink("t.hf", "a # b");
  auto t = lex("a # b", sink);
  EXPECT_EQ(sink.errorCount(), 1u);
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[1].text, "b");
  auto d = sink.take();
  EXPECT_EQ(d[0].message, "unexpected character '#'");
  EXPECT_EQ(d[0].column, 3);
}

TEST(LangLexer, NonPrintableByteIsShownInHex) {
  std::string src = "a \x01";
  DiagnosticSink sink("t.hf", src);
  lex(src, sink);
  auto d = sink.take();
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].message, "unexpected character byte 0x01");
}

}  // namespace
}  // namespace frep::lang
