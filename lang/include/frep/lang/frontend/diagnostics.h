// Collects errors and warnings with their place in the source, and suggests close names.
#pragma once

#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "frep/lang/frontend/ast.h"
#include "frep/lang/hyperfun.h"

namespace frep::lang {

class DiagnosticSink {
 public:
  // Stops recording errors past this many (a runaway cascade helps nobody).
  static constexpr size_t kMaxErrors = 100;

  DiagnosticSink(std::string file, const std::string& source);

  void error(Loc loc, const std::string& message);
  void warning(Loc loc, const std::string& message);
  size_t errorCount() const { return errors_; }
  bool full() const { return errors_ >= kMaxErrors; }
  // Diagnostics sorted by place (stable); unplaced ones last.
  std::vector<Diagnostic> take();

 private:
  void add(Diagnostic::Severity sev, Loc loc, const std::string& message);
  std::string file_;
  std::vector<std::string> lines_;
  std::vector<Diagnostic> diags_;
  std::set<std::tuple<int, int, std::string>> seen_;  // the same error once (unrolled loops)
  size_t errors_ = 0;
};

// Levenshtein distance (case-sensitive).
size_t editDistance(const std::string& a, const std::string& b);
// The closest candidate to name ignoring case (returned as spelled), or "" when none is close
// enough to be a plausible typo.
std::string closestName(const std::string& name, const std::vector<std::string>& candidates);

}  // namespace frep::lang
