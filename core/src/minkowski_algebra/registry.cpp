// The table of exact Minkowski terms, keyed by hash-consed node (registry.h).
#include "frep/minkowski_algebra/registry.h"

#include <cstdio>

#include <mutex>
#include <unordered_map>

namespace frep::minkowski {
namespace {
struct Entry {
  NodePtr keep;  // keeps the node (and so its address) alive
  ExactTerm term;
};
std::mutex gMutex;
// Never destroyed: its nodes must not outlive the intern table's static destruction.
std::unordered_map<const Node*, Entry>& table() {
  static auto* t = new std::unordered_map<const Node*, Entry>();
  return *t;
}
}  // namespace

void registerExact(const Expr& e, const ExactTerm& t) {
  std::lock_guard<std::mutex> lock(gMutex);
  table()[&e.node()] = Entry{e.ptr(), t};
}

std::optional<ExactTerm> lookupExact(const Expr& e) {
  std::lock_guard<std::mutex> lock(gMutex);
  auto it = table().find(&e.node());
  if (it == table().end()) return std::nullopt;
  return it->second.term;
}

namespace {
std::string boundText(double sampled) {
  if (!(sampled > 0)) return "error bound 0 (no search)";
  char buf[96];
  std::snprintf(buf, sizeof buf, "error bound %.3g (the sampled operand's; no search)", sampled);
  return buf;
}
}  // namespace

std::vector<std::string> describeExact(const Expr& f) {
  std::vector<std::string> lines;
  forEachNode(f, [&](const Node& n) {
    std::lock_guard<std::mutex> lock(gMutex);
    auto it = table().find(&n);
    if (it == table().end()) return;
    const ExactTerm& t = it->second.term;
    if (t.kind == ExactTerm::Kind::Sum && t.sum.terms < 2) return;  // a member alone: no operation
    if (t.kind == ExactTerm::Kind::Distance) return;                  // a primitive, no operation
    if (t.kind == ExactTerm::Kind::BallOffset)
      lines.push_back(std::string("exact Minkowski ") + (t.erosion ? "difference " : "sum ") + t.operand +
                      " as the offset f " + (t.erosion ? "- " : "+ ") + "r of an exact signed distance, " +
                      boundText(t.errorBound));
    else if (t.kind == ExactTerm::Kind::MeshPolytope)
      lines.push_back(std::string("exact Minkowski ") + (t.erosion ? "difference " : "sum ") + t.operand + ", " +
                      boundText(t.errorBound));
    else if (t.kind == ExactTerm::Kind::Sum)
      lines.push_back("exact Minkowski algebra (Roerdink): " + t.sum.describe() + " as a union of " +
                      std::to_string(t.pieces) + " primitives, error bound 0 (no search)");
    else
      lines.push_back("exact Minkowski subtraction chain (Roerdink eq. 19-21): " + t.c0.describe() +
                      " minus " + t.sum.describe() + " as an intersection of " +
                      std::to_string(t.pieces) + " terms, error bound 0 (no search)");
  });
  return lines;
}

}  // namespace frep::minkowski
