// The registry of library functions (hf*, fr*), filled at static-init time.
#include "frep/lang/library/library.h"

#include <algorithm>
#include <cctype>

namespace frep::lang {
namespace {

std::string lowerCase(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// Function-local static: registrations from other translation units may run before any
// namespace-scope object of this file is constructed.
std::vector<LibraryFunction>& registry() {
  static std::vector<LibraryFunction> fns;
  return fns;
}

bool lessByName(const LibraryFunction& a, const LibraryFunction& b) {
  std::string la = lowerCase(a.name), lb = lowerCase(b.name);
  return la != lb ? la < lb : a.name < b.name;
}

}  // namespace

void registerLibraryFunction(LibraryFunction fn) {
  auto& fns = registry();
  std::string key = lowerCase(fn.name);
  // A second registration of a name replaces the first (tests register fakes this way).
  auto same = std::find_if(fns.begin(), fns.end(),
                           [&](const LibraryFunction& f) { return lowerCase(f.name) == key; });
  if (same != fns.end()) fns.erase(same);
  auto pos = std::upper_bound(fns.begin(), fns.end(), fn, lessByName);
  fns.insert(pos, std::move(fn));
}

const LibraryFunction* findLibraryFunction(std::string_view name) {
  std::string key = lowerCase(name);
  const auto& fns = registry();
  // Sorted by lower-cased name, so a binary search finds it.
  auto it = std::lower_bound(fns.begin(), fns.end(), key, [](const LibraryFunction& f,
                                                              const std::string& k) {
    return lowerCase(f.name) < k;
  });
  if (it != fns.end() && lowerCase(it->name) == key) return &*it;
  return nullptr;
}

const std::vector<LibraryFunction>& libraryFunctions() { return registry(); }

bool registerAll(std::vector<LibraryFunction> fns) {
  for (auto& f : fns) registerLibraryFunction(std::move(f));
  return true;
}

}  // namespace frep::lang
