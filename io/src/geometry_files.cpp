// The per-process cache of geometry files (geometry_files.h): key = kind, grid and the content
// hash of the bytes, so an edited file is read again and an unchanged one never twice.
#include "frep/io/geometry_files.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <tuple>

#include "frep/geometry/distance_fields.h"
#include "frep/io/error.h"
#include "frep/io/input_file.h"
#include "frep/io/mesh_reader.h"
#include "frep/lang/library/library.h"

namespace frep::io {

uint64_t contentHash(const std::string& bytes) {
  uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ULL;
  return h;
}

namespace {
std::string readAll(const std::string& path) { return readInputFile(path); }

std::string edgeList(const MeshCheck& c) {
  std::string s;
  for (auto& e : c.firstOpen) s += (s.empty() ? "" : ", ") + std::to_string(e[0] + 1) + "-" + std::to_string(e[1] + 1);
  return s;
}
}  // namespace

LoadedGeometry loadGeometry(const std::string& path, const std::string& bytes, const std::string& kind,
                            const std::string& grid) {
  static std::mutex mu;
  static std::map<std::tuple<std::string, std::string, uint64_t>, LoadedGeometry> cache;
  const uint64_t hash = contentHash(bytes);
  // A mesh's format is its extension: the same bytes as .obj and .stl are different meshes.
  const auto key = std::make_tuple(kind + (kind == "mesh" ? "." + lowerExtension(path) : ""), grid, hash);
  {
    std::lock_guard<std::mutex> lock(mu);
    auto it = cache.find(key);
    if (it != cache.end()) return it->second;
  }
  LoadedGeometry g;
  g.fileHash = hash;
  if (kind == "mesh") {
    Mesh m = parseMesh(path, bytes);
    std::vector<double> xyz;
    std::vector<uint32_t> tris;
    xyz.reserve(3 * m.positions.size());
    tris.reserve(3 * m.triangles.size());
    for (const auto& p : m.positions) xyz.insert(xyz.end(), p.begin(), p.end());
    for (const auto& t : m.triangles) tris.insert(tris.end(), t.begin(), t.end());
    std::shared_ptr<MeshField> f;
    try {
      f = std::make_shared<MeshField>(std::move(xyz), std::move(tris), path);
    } catch (const std::invalid_argument& e) {
      throw Error(kExitModelError, path + ": " + e.what());
    }
    const MeshCheck& c = f->check();
    if (!c.closed())
      g.warnings.push_back("'" + path + "' is not closed: " + std::to_string(c.openEdges) + " open edges (first: " +
                           edgeList(c) + ", vertices after welding), " + std::to_string(c.nonManifoldEdges) +
                           " non-manifold; inside is where the generalised winding number exceeds 1/2 "
                           "(O(triangles) per point)");
    if (c.degenerateTriangles)
      g.warnings.push_back("'" + path + "': " + std::to_string(c.degenerateTriangles) + " degenerate triangles ignored");
    g.field = f;
  } else if (kind == "volume") {
    g.field = readVolumeField(path, bytes, grid, hash);
  } else {
    throw Error(kExitInternal, "unknown geometry kind '" + kind + "'");
  }
  std::lock_guard<std::mutex> lock(mu);
  return cache.emplace(key, g).first->second;
}

LoadedGeometry loadGeometryFile(const std::string& path, const std::string& kind, const std::string& grid) {
  return loadGeometry(path, readAll(path), kind, grid);
}

void installGeometryLoader() {
  lang::setFileFieldLoader([](const lang::FileFieldRequest& r) {
    LoadedGeometry g = loadGeometry(r.path, *r.bytes, r.kind, r.grid);
    return lang::LoadedFileField{g.field, g.fileHash, g.warnings};
  });
}

}  // namespace frep::io
