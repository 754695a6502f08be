// Fuzz target: frep pov's scene preprocessor (io/src/pov_scene.cpp, translateScene: POV text with
// `$ … <+> … $` Minkowski terms) on arbitrary text (fuzz_target.h). It may only refuse with a
// PovError that names the place (fuzz.pov:line:column); what it writes contains no non-finite
// number (POV-Ray would read `inf` or `nan` as an identifier).
#include <cctype>
#include <string>

#include "frep/io/pov_scene.h"
#include "fuzz_target.h"

namespace {
// Whether `text` has the word `word` (not inside a longer identifier).
bool hasWord(const std::string& text, const std::string& word) {
  for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
    const bool before = at == 0 || !(std::isalnum(static_cast<unsigned char>(text[at - 1])) || text[at - 1] == '_');
    const size_t end = at + word.size();
    const bool after = end >= text.size() || !(std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_');
    if (before && after) return true;
  }
  return false;
}

// How many times `text` has `part`.
size_t count(const std::string& text, const char* part) {
  size_t n = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}
}  // namespace

void frep::fuzz::pov(const uint8_t* data, size_t size) {
  if (size > 4096) return;
  const std::string text(reinterpret_cast<const char*>(data), size);
  // A sum with discs on three axes, or on two and a sphere, has a tridiscsphere corner, which
  // frep pov polygonises at 44^3 from its exact field: 5 s in the Release build, 50-90 s of CPU
  // under the sanitizers, a timeout for every such input. Those are skipped: this target fuzzes
  // the preprocessor's parsing and the primitives' text, not that mesher (tests/core has it).
  const size_t discs = count(text, "disc");
  if (discs >= 3 || (discs >= 2 && count(text, "sphere") > 0)) return;
  std::string out;
  try {
    out = io::translateScene(text, "fuzz.pov", 0.01);
  } catch (const io::PovError& e) {
    FREP_FUZZ_CHECK(std::string(e.what()).rfind("fuzz.pov:", 0) == 0);
    return;
  }
  // What the scene had is copied; what the preprocessor wrote must be finite.
  for (const char* bad : {"inf", "nan", "-inf", "-nan"})
    FREP_FUZZ_CHECK(!hasWord(out, bad) || hasWord(text, bad));
}

FREP_FUZZ_ENTRY(frep::fuzz::pov)
