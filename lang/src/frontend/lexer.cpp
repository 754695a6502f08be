#include "frep/lang/frontend/lexer.h"

#include <cctype>
#include <charconv>
#include <unordered_map>

namespace frep::lang {

std::string tokenName(Tok kind) {
  switch (kind) {
    case Tok::End: return "end of file";
    case Tok::String: return "a string";
    case Tok::Number: return "a number";
    case Tok::Ident: return "a name";
    case Tok::Plus: return "'+'";
    case Tok::Minus: return "'-'";
    case Tok::Star: return "'*'";
    case Tok::Slash: return "'/'";
    case Tok::Caret: return "'^'";
    case Tok::Tilde: return "'~'";
    case Tok::Amp: return "'&'";
    case Tok::Bar: return "'|'";
    case Tok::Backslash: return "'\\'";
    case Tok::At: return "'@'";
    case Tok::Comma: return "','";
    case Tok::Semi: return "';'";
    case Tok::Assign: return "'='";
    case Tok::LParen: return "'('";
    case Tok::RParen: return "')'";
    case Tok::LBracket: return "'['";
    case Tok::RBracket: return "']'";
    case Tok::LBrace: return "'{'";
    case Tok::RBrace: return "'}'";
    case Tok::Lt: return "'<'";
    case Tok::Le: return "'<='";
    case Tok::Gt: return "'>'";
    case Tok::Ge: return "'>='";
    case Tok::Ne: return "'/='";
    case Tok::KwArray: return "'array'";
    case Tok::KwIf: return "'if'";
    case Tok::KwThen: return "'then'";
    case Tok::KwElse: return "'else'";
    case Tok::KwEndif: return "'endif'";
    case Tok::KwWhile: return "'while'";
    case Tok::KwLoop: return "'loop'";
    case Tok::KwEndloop: return "'endloop'";
    case Tok::KwAnd: return "'and'";
    case Tok::KwOr: return "'or'";
    case Tok::KwNot: return "'not'";
  }
  return "?";
}

namespace {

const std::unordered_map<std::string, Tok>& keywords() {
  static const std::unordered_map<std::string, Tok> k = {
      {"array", Tok::KwArray}, {"if", Tok::KwIf},       {"then", Tok::KwThen},
      {"else", Tok::KwElse},   {"endif", Tok::KwEndif}, {"while", Tok::KwWhile},
      {"loop", Tok::KwLoop},   {"endloop", Tok::KwEndloop}, {"and", Tok::KwAnd},
      {"or", Tok::KwOr},       {"not", Tok::KwNot}};
  return k;
}

bool isDigit(char c) { return c >= '0' && c <= '9'; }
bool isAlpha(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }

class Lexer {
 public:
  Lexer(const std::string& s, DiagnosticSink& d) : src_(s), diags_(d) {}

  std::vector<Token> run() {
    std::vector<Token> out;
    while (true) {
      skipSpaceAndComments();
      Token t;
      t.loc = here();
      if (pos_ >= src_.size()) {
        t.kind = Tok::End;
        out.push_back(t);
        return out;
      }
      char c = src_[pos_];
      if (isAlpha(c) || c == '_') {
        lexIdent(t);
      } else if (isDigit(c) || (c == '.' && pos_ + 1 < src_.size() && isDigit(src_[pos_ + 1]))) {
        lexNumber(t);
      } else if (!lexPunct(t)) {
        continue;
      }
      out.push_back(std::move(t));
    }
  }

 private:
  Loc here() const { return Loc{line_, static_cast<int>(pos_ - lineStart_) + 1}; }
  void advance() {
    if (src_[pos_] == '\n') {
      ++line_;
      lineStart_ = pos_ + 1;
    }
    ++pos_;
  }
  char peek(size_t k = 0) const { return pos_ + k < src_.size() ? src_[pos_ + k] : '\0'; }

  void skipSpaceAndComments() {
    while (pos_ < src_.size()) {
      char c = src_[pos_];
      if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v') {
        advance();
      } else if (c == '-' && peek(1) == '-') {
        while (pos_ < src_.size() && src_[pos_] != '\n') advance();
      } else {
        break;
      }
    }
  }

  void lexIdent(Token& t) {
    size_t start = pos_;
    while (pos_ < src_.size() && (isAlpha(src_[pos_]) || isDigit(src_[pos_]) || src_[pos_] == '_'))
      advance();
    t.text = src_.substr(start, pos_ - start);
    t.lower = t.text;
    for (auto& ch : t.lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    auto it = keywords().find(t.lower);
    t.kind = it != keywords().end() ? it->second : Tok::Ident;
  }

  // D+[.D*][(e|E)[+-]D+] or .D+[(e|E)[+-]D+]. A bad number is reported and still yields a
  // Number token, so the parser does not report a second error for the same mistake.
  void lexNumber(Token& t) {
    size_t start = pos_;
    while (isDigit(peek())) advance();
    if (peek() == '.') {
      advance();
      while (isDigit(peek())) advance();
    }
    bool bad = false;
    if (peek() == 'e' || peek() == 'E') {
      size_t k = 1;
      if (peek(1) == '+' || peek(1) == '-') k = 2;
      if (isDigit(peek(k))) {
        for (size_t i = 0; i < k; ++i) advance();
        while (isDigit(peek())) advance();
      } else {
        bad = true;
      }
    }
    // A number runs straight into a name: "2e" or "3abc".
    if (isAlpha(peek()) || peek() == '_' || peek() == '.') bad = true;
    t.kind = Tok::Number;
    if (bad) {
      while (isAlpha(peek()) || isDigit(peek()) || peek() == '_' || peek() == '.') advance();
      t.text = src_.substr(start, pos_ - start);
      diags_.error(t.loc, "malformed number '" + t.text + "'");
      return;
    }
    t.text = src_.substr(start, pos_ - start);
    auto res = std::from_chars(t.text.data(), t.text.data() + t.text.size(), t.number);
    if (res.ec != std::errc()) {
      t.number = 0.0;
      diags_.error(t.loc, "number '" + t.text + "' is out of range");
    }
  }

  bool lexPunct(Token& t) {
    char c = src_[pos_];
    auto one = [&](Tok k) {
      t.kind = k;
      t.text = std::string(1, c);
      advance();
      return true;
    };
    auto two = [&](Tok k) {
      t.kind = k;
      t.text = src_.substr(pos_, 2);
      advance();
      advance();
      return true;
    };
    switch (c) {
      case '+': return one(Tok::Plus);
      case '-': return one(Tok::Minus);
      case '*': return one(Tok::Star);
      case '/': return peek(1) == '=' ? two(Tok::Ne) : one(Tok::Slash);
      case '^': return one(Tok::Caret);
      case '~': return one(Tok::Tilde);
      case '&': return one(Tok::Amp);
      case '|': return one(Tok::Bar);
      case '\\': return one(Tok::Backslash);
      case '@': return one(Tok::At);
      case ',': return one(Tok::Comma);
      case ';': return one(Tok::Semi);
      case '=': return one(Tok::Assign);
      case '(': return one(Tok::LParen);
      case ')': return one(Tok::RParen);
      case '[': return one(Tok::LBracket);
      case ']': return one(Tok::RBracket);
      case '{': return one(Tok::LBrace);
      case '}': return one(Tok::RBrace);
      case '<': return peek(1) == '=' ? two(Tok::Le) : one(Tok::Lt);
      case '>': return peek(1) == '=' ? two(Tok::Ge) : one(Tok::Gt);
      default: break;
    }
    Loc loc = here();
    if (c == '!' && peek(1) == '=') {
      diags_.error(loc, "unexpected '!='; HyperFun writes 'not equal' as '/='");
      return two(Tok::Ne);
    }
    if (c == '"') {  // a file name (frVolumeSplineFile); one line, no escapes
      advance();
      const size_t start = pos_;
      while (pos_ < src_.size() && src_[pos_] != '"' && src_[pos_] != '\n') advance();
      if (pos_ >= src_.size() || src_[pos_] != '"') {
        diags_.error(loc, "unterminated string (a string ends with '\"' on the same line)");
        return false;
      }
      t.kind = Tok::String;
      t.text = src_.substr(start, pos_ - start);
      advance();
      return true;
    }
    unsigned char u = static_cast<unsigned char>(c);
    std::string shown = std::isprint(u) ? std::string("'") + c + "'" : "byte 0x" + hex(u);
    diags_.error(loc, "unexpected character " + shown);
    advance();
    return false;
  }

  static std::string hex(unsigned char u) {
    const char* d = "0123456789abcdef";
    return std::string{d[u >> 4], d[u & 15]};
  }

  const std::string& src_;
  DiagnosticSink& diags_;
  size_t pos_ = 0, lineStart_ = 0;
  int line_ = 1;
};

}  // namespace

std::vector<Token> lex(const std::string& source, DiagnosticSink& diags) {
  return Lexer(source, diags).run();
}

}  // namespace frep::lang
