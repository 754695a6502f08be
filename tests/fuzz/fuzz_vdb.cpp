// Fuzz target: frep mesh's .vdb reader (io/src/vdb_reader.cpp) on arbitrary files, then the
// mesher on what it accepts, as frep mesh in.vdb does (fuzz_target.h). OpenVDB itself is not
// instrumented; frepfarm's checks in front of it must refuse whatever would make it misbehave.
// The first byte's low bit asks to re-seal the file (recompute its frep_grid_checksum), as an
// attacker can: crafted files. That mode needs FREP_FUZZ_VDB_CRAFTED=1 and is off in CI: it found
// a heap overflow inside OpenVDB's block decompression (a negative stored block size), which now
// happens only in the child process the reader parses files in (io/src/vdb_isolation.h; not yet
// re-run under the sanitizers, docs/cli.md "Fuzzing"). CI fuzzes damage to sealed files: inputs
// that the reader's own layout check (vdb_layout.h) still finds sealed, i.e. the seal's entry survived
// where the reader looks for it.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "../../io/src/vdb_checksum.h"
#include "../../io/src/vdb_layout.h"
#include "frep/io/error.h"
#include "frep/io/vdb_reader.h"
#include "frep/meshing/mesh_grid.h"
#include "fuzz_target.h"

namespace {

std::string sealEntry() {
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::string key = frep::io::kGridChecksumKey;
  return u32(uint32_t(key.size())) + key + u32(6) + "string" + u32(uint32_t(frep::io::kChecksumDigits));
}

void reseal(std::string& bytes) {
  const std::string entry = sealEntry();
  const size_t at = bytes.find(entry);
  if (at == std::string::npos || at + entry.size() + frep::io::kChecksumDigits > bytes.size()) return;
  const size_t digits = at + entry.size();
  bytes.replace(digits, frep::io::kChecksumDigits, frep::io::vdbChecksum(bytes, digits));
}

}  // namespace

void frep::fuzz::vdb(const uint8_t* data, size_t size) {
  if (size == 0) return;
  std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  static const bool crafted = std::getenv("FREP_FUZZ_VDB_CRAFTED") != nullptr;
  if (crafted && (data[0] & 1)) reseal(bytes);
  if (!crafted && bytes.find(sealEntry()) == std::string::npos) return;
  static const std::string path = "/tmp/frep_fuzz_vdb." + std::to_string(::getpid()) + ".vdb";
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(bytes.data(), 1, bytes.size(), f);
    std::fclose(f);
  }
  try {
    // Damage mode: a file whose seal entry itself was damaged (moved out of the grid's metadata,
    // or its key or length changed) reads as another tool's unsealed file, whose grids only
    // OpenVDB checks (in the reader's child process): not fuzzed in CI.
    if (!crafted && !io::checkVdbLayout(path).sealed) {
      std::remove(path.c_str());
      return;
    }
    const io::SampledVdb v = io::readSampledVdb(path, "");
    if (v.samples.leaves.size() <= 4096) {
      SampledMeshOptions options;
      options.threads = 1;
      (void)meshSamples(v.samples, options);
    }
  } catch (const io::Error& e) {
    FREP_FUZZ_CHECK(e.code == io::kExitIoError || e.code == io::kExitModelError);
  }
  std::remove(path.c_str());
}

FREP_FUZZ_ENTRY(frep::fuzz::vdb)
