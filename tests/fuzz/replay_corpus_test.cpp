// The fuzz corpora (tests/fuzz/corpus/<target>/: seeds and every crasher a fuzz run found) replayed
// through the fuzz targets' own entry points in the normal build, so a fixed finding stays fixed
// without clang or sanitizers. A finding aborts (fuzz_target.h), failing the test.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "fuzz_target.h"

namespace {

size_t replay(const std::string& target, void (*entry)(const uint8_t*, size_t)) {
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(std::string(FREP_FUZZ_CORPUS_DIR) + "/" + target)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path(), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    SCOPED_TRACE(e.path().string());
    entry(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    ++files;
  }
  return files;
}

}  // namespace

TEST(FuzzCorpus, HfFrontEnd) { EXPECT_GT(replay("hf", frep::fuzz::hf), 0u); }
TEST(FuzzCorpus, PayloadCodec) { EXPECT_GT(replay("payload", frep::fuzz::payload), 0u); }
TEST(FuzzCorpus, JournalReader) { EXPECT_GT(replay("journal", frep::fuzz::journal), 0u); }
TEST(FuzzCorpus, MeshReaders) { EXPECT_GT(replay("mesh", frep::fuzz::mesh), 0u); }
TEST(FuzzCorpus, PovScene) { EXPECT_GT(replay("pov", frep::fuzz::pov), 0u); }
// Crafted files too (re-sealed after damage, fuzz_vdb.cpp): the kept finding is one.
TEST(FuzzCorpus, VdbReader) {
  ::setenv("FREP_FUZZ_VDB_CRAFTED", "1", 1);
  EXPECT_GT(replay("vdb", frep::fuzz::vdb), 0u);
}
