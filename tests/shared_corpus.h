// The third-party test data in ../shared (FREP_SHARED_DIR, tests/CMakeLists.txt). A test that
// reads it skips when the folder is absent on a developer's machine, but fails when the
// environment sets FREP_REQUIRE_CORPUS (to anything but 0): CI does (deploy/test.sh), so a CI run
// without the data cannot turn green by skipping.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace frep_test {

inline bool corpusRequired() {
  const char* v = std::getenv("FREP_REQUIRE_CORPUS");
  return v != nullptr && *v != '\0' && std::strcmp(v, "0") != 0;
}

}  // namespace frep_test

// In SetUp (or a test body): returns from it, skipped or failed, when `dir` is not a folder.
#define FREP_NEED_CORPUS(dir)                                                                             \
  do {                                                                                                    \
    if (!std::filesystem::is_directory(dir)) {                                                            \
      if (frep_test::corpusRequired())                                                                    \
        FAIL() << "corpus not found at " << (dir)                                                         \
               << " (FREP_REQUIRE_CORPUS is set, as in CI: ../shared must be there)";                     \
      GTEST_SKIP() << "corpus not found at " << (dir) << " (FREP_REQUIRE_CORPUS=1 makes this a failure)"; \
    }                                                                                                     \
  } while (0)
