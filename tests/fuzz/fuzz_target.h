// The fuzz targets' shared frame: each fuzz_<name>.cpp defines frep::fuzz::<name>(data, size),
// the entry point that libFuzzer drives (run_fuzz.sh, built with FREP_LIBFUZZER under
// ASan+UBSan) and that replay_corpus_test.cpp replays over tests/fuzz/corpus/<name>/ in the
// normal build. An oracle that does not hold aborts, so both report it as a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#define FREP_FUZZ_CHECK(cond)                                                          \
  do {                                                                                 \
    if (!(cond)) {                                                                     \
      std::fprintf(stderr, "%s:%d: fuzz oracle failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                    \
    }                                                                                  \
  } while (0)

#ifdef FREP_LIBFUZZER
#define FREP_FUZZ_ENTRY(fn) \
  extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) { return fn(data, size), 0; }
#else
#define FREP_FUZZ_ENTRY(fn)
#endif

namespace frep::fuzz {
void hf(const uint8_t* data, size_t size);
void payload(const uint8_t* data, size_t size);
void journal(const uint8_t* data, size_t size);
void vdb(const uint8_t* data, size_t size);
void mesh(const uint8_t* data, size_t size);
void pov(const uint8_t* data, size_t size);
}  // namespace frep::fuzz
