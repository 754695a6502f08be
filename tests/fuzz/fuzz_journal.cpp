// libFuzzer target: the master's journal reader (master/journal.cpp) on arbitrary bytes, replayed
// as --resume would. Built only by tests/fuzz/CMakeLists.txt under ASan+UBSan (see run_fuzz.sh).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "journal.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = "/tmp/frep_fuzz_journal." + std::to_string(::getpid());
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  try {
    size_t bytes = 0;
    frep::farm::Journal j(path, 42, true, [&](uint64_t, const std::string& payload) { bytes += payload.size(); });
    if (bytes > size) __builtin_trap();  // a replayed payload can only come from the file
  } catch (const std::runtime_error&) {
    // another job's journal, or not a journal: refused, as --resume does
  }
  return 0;
}
