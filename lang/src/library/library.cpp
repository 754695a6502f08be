// The registry of library functions (hf*, fr*), filled at static-init time.
#include "frep/lang/library/library.h"

#include <algorithm>

namespace frep::lang {
namespace {

std::string lowerCase(std::string_view s) {
  std::string out(s);
  for (auto& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');  // names are ASCII: no locale
  return out;
}

// Function-local static: registrations from other translation units may run before any
// namespace-scope object of this file is constructed. Sorted by lower-cased name, each
// function's lower-cased name kept beside it: every program registers a few hundred functions
// at start-up, and lower-casing both sides of every comparison there cost ~1 ms a process.
struct Registry {
  std::vector<LibraryFunction> fns;
  std::vector<std::string> keys;  // keys[i]: fns[i].name lower-cased
};
Registry& registry() {
  static Registry r;
  return r;
}

}  // namespace

void registerLibraryFunction(LibraryFunction fn) {
  Registry& r = registry();
  std::string key = lowerCase(fn.name);
  // Sorted by the keys, which are unique: a second registration of a name replaces the first
  // in place (tests register fakes this way).
  const auto it = std::lower_bound(r.keys.begin(), r.keys.end(), key);
  const size_t at = size_t(it - r.keys.begin());
  if (it != r.keys.end() && *it == key) {
    r.fns[at] = std::move(fn);
    return;
  }
  r.fns.insert(r.fns.begin() + std::ptrdiff_t(at), std::move(fn));
  r.keys.insert(it, std::move(key));
}

const LibraryFunction* findLibraryFunction(std::string_view name) {
  const std::string key = lowerCase(name);
  const Registry& r = registry();
  auto it = std::lower_bound(r.keys.begin(), r.keys.end(), key);
  if (it != r.keys.end() && *it == key) return &r.fns[size_t(it - r.keys.begin())];
  return nullptr;
}

const std::vector<LibraryFunction>& libraryFunctions() { return registry().fns; }

bool registerAll(std::vector<LibraryFunction> fns) {
  for (auto& f : fns) registerLibraryFunction(std::move(f));
  return true;
}

}  // namespace frep::lang
