#include "frep/lang/frontend/diagnostics.h"

#include <algorithm>
#include <cctype>

namespace frep::lang {

std::string Diagnostic::format() const {
  const char* sev = severity == Severity::Error ? "error"
                    : severity == Severity::Warning ? "warning" : "note";
  std::string out = file;
  if (line > 0) out += ":" + std::to_string(line) + ":" + std::to_string(column);
  out += std::string(": ") + sev + ": " + message;
  if (line > 0 && !sourceLine.empty()) {
    out += "\n  " + sourceLine + "\n  ";
    // Keep tabs so the caret lines up under the same display column.
    for (int i = 0; i + 1 < column && i < static_cast<int>(sourceLine.size()); ++i)
      out += sourceLine[i] == '\t' ? '\t' : ' ';
    out += '^';
  }
  return out;
}

DiagnosticSink::DiagnosticSink(std::string file, const std::string& source)
    : file_(std::move(file)) {
  std::string cur;
  for (char c : source) {
    if (c == '\n') {
      lines_.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  lines_.push_back(cur);
}

void DiagnosticSink::add(Diagnostic::Severity sev, Loc loc, const std::string& message) {
  if (!seen_.insert({loc.line, loc.column, message}).second) return;
  Diagnostic d;
  d.severity = sev;
  d.file = file_;
  d.line = loc.line;
  d.column = loc.column;
  d.message = message;
  if (loc.line >= 1 && loc.line <= static_cast<int>(lines_.size())) d.sourceLine = lines_[loc.line - 1];
  diags_.push_back(std::move(d));
}

void DiagnosticSink::error(Loc loc, const std::string& message) {
  if (full()) return;
  size_t before = diags_.size();
  add(Diagnostic::Severity::Error, loc, message);
  if (diags_.size() == before) return;
  if (++errors_ == kMaxErrors)
    add(Diagnostic::Severity::Note, Loc{}, "too many errors; stopping here");
}

void DiagnosticSink::warning(Loc loc, const std::string& message) {
  add(Diagnostic::Severity::Warning, loc, message);
}

std::vector<Diagnostic> DiagnosticSink::take() {
  std::stable_sort(diags_.begin(), diags_.end(), [](const Diagnostic& a, const Diagnostic& b) {
    auto key = [](const Diagnostic& d) {
      return std::make_pair(d.line == 0 ? 1 << 30 : d.line, d.column);
    };
    return key(a) < key(b);
  });
  seen_.clear();
  return std::move(diags_);
}

size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string closestName(const std::string& name, const std::vector<std::string>& candidates) {
  auto lower = [](std::string s) {
    for (auto& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    return s;
  };
  std::string key = lower(name), best;
  size_t bestDist = 0;
  for (const auto& c : candidates) {
    std::string lc = lower(c);
    if (lc == key) continue;
    size_t d = editDistance(key, lc);
    if (best.empty() || d < bestDist || (d == bestDist && c < best)) {
      best = c;
      bestDist = d;
    }
  }
  // A typo changes about a third of a name at most; anything further is noise.
  // One-letter names are all one edit apart: suggesting any of them would be noise.
  size_t limit = std::max<size_t>(1, (name.size() + 2) / 3);
  return (!best.empty() && bestDist <= limit && bestDist < key.size()) ? best : std::string();
}

}  // namespace frep::lang
