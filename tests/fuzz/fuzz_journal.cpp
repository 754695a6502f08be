// Fuzz target: the master's journal reader (master/journal.cpp) on arbitrary bytes, replayed as
// --resume would (fuzz_target.h).
#include <unistd.h>

#include <cstdio>
#include <stdexcept>
#include <string>

#include "fuzz_target.h"
#include "frep/master/journal.h"

void frep::fuzz::journal(const uint8_t* data, size_t size) {
  static const std::string path = "/tmp/frep_fuzz_journal." + std::to_string(::getpid());
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  try {
    size_t bytes = 0;
    frep::farm::Journal j(path, 42, true, [&](uint64_t, const std::string& payload) { bytes += payload.size(); });
    FREP_FUZZ_CHECK(bytes <= size);  // a replayed payload can only come from the file
  } catch (const std::runtime_error&) {
    // another job's journal, or not a journal: refused, as --resume does
  }
  std::remove(path.c_str());
}

FREP_FUZZ_ENTRY(frep::fuzz::journal)
