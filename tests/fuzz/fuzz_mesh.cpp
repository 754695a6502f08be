// Fuzz target: the mesh readers of frep render and frMesh (io/src/mesh_reader.cpp: PLY ascii and
// binary little/big endian, OBJ, STL ascii and binary) on arbitrary bytes (fuzz_target.h). The
// first byte chooses the format (its value mod 3: .stl, .obj, .ply), the rest is the file. A
// reader may only refuse with an I/O error (exit 3) naming the file; what it accepts is a mesh
// with triangles, finite coordinates and every index in range, no larger than the file can
// describe (issue 31: counts in headers were trusted).
#include <cmath>
#include <string>

#include "frep/io/error.h"
#include "frep/io/mesh_reader.h"
#include "fuzz_target.h"

void frep::fuzz::mesh(const uint8_t* data, size_t size) {
  if (size == 0 || size > (1 << 20)) return;
  static const char* const names[3] = {"fuzz.stl", "fuzz.obj", "fuzz.ply"};
  const std::string name = names[data[0] % 3];
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  Mesh m;
  try {
    m = io::parseMesh(name, bytes);
  } catch (const io::Error& e) {
    FREP_FUZZ_CHECK(e.code == io::kExitIoError);
    FREP_FUZZ_CHECK(std::string(e.what()).rfind(name, 0) == 0);  // names the file first
    return;
  }
  FREP_FUZZ_CHECK(!m.triangles.empty());
  for (const auto& p : m.positions)
    for (double c : p) FREP_FUZZ_CHECK(std::isfinite(c));
  for (const auto& t : m.triangles)
    for (uint32_t i : t) FREP_FUZZ_CHECK(i < m.positions.size());
  // Every vertex takes at least 3 bytes of the file (three 1-byte PLY scalars), every triangle
  // at least one (a fanned PLY polygon of 1-byte indices; a binary STL facet takes 50 for 3
  // vertices): nothing larger than the file describes.
  FREP_FUZZ_CHECK(m.positions.size() <= bytes.size() / 3 + 1);
  FREP_FUZZ_CHECK(m.triangles.size() <= bytes.size());
}

FREP_FUZZ_ENTRY(frep::fuzz::mesh)
