// A FloatGrid (frep sample's output) read back as sampled values for meshSamples; see
// vdb_reader.h. One of the two translation units of frep that include OpenVDB.
#include "frep/io/vdb_reader.h"

#include <openvdb/openvdb.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <new>
#include <unordered_set>
#include <vector>

#include "allocation_cap.h"
#include "checked_grid.h"
#include "vdb_checksum.h"
#include "vdb_backend.h"
#include "vdb_isolation.h"

#include "frep/io/format_number.h"
#include "frep/io/error.h"

namespace frep::io {
namespace {

std::string gridList(const openvdb::GridPtrVec& grids) {
  if (grids.empty()) return "it holds no grids";
  std::string s = "it holds";
  for (size_t i = 0; i < grids.size(); ++i)
    s += std::string(i ? "," : "") + " '" + grids[i]->getName() + "' (" + grids[i]->valueType() + ")";
  return s;
}

// An 8^3 block by its origin relative to the grid's lowest leaf origin `lo` (non-negative, and
// below 2^19 + 8 voxels: 21 bits per axis).
uint64_t blockId(const int64_t lo[3], int64_t x, int64_t y, int64_t z) {
  return (uint64_t((x - lo[0]) >> 3) << 42) | (uint64_t((y - lo[1]) >> 3) << 21) | uint64_t((z - lo[2]) >> 3);
}

// The largest single allocation OpenVDB may make while it reads a file of `fileBytes`: a node's
// values (at most 256 KiB for a float tree) or a compressed block (at most the file).
size_t allocationCapFor(uint64_t fileBytes) { return size_t(64 << 20) + size_t(fileBytes); }

}  // namespace

namespace {

// OpenVDB's parse of `path` (its layout checked), in this process: the grid `request` asks for.
openvdb::FloatGrid::Ptr parseFloatGrid(const std::string& path, const GridRequest& request, uint64_t bytes) {
  const std::string& shown = request.shown;
  auto named = [&](std::string msg) {  // messages of OpenVDB name the path read
    if (shown == path) return msg;
    for (size_t at = msg.find(path); at != std::string::npos; at = msg.find(path, at + shown.size()))
      msg.replace(at, path.size(), shown);
    return msg;
  };
  openvdb::FloatGrid::Ptr grid;
  std::string chosenName;
  try {
    const AllocationCap cap(allocationCapFor(bytes));
    openvdb::io::File file(path);
    file.open(false);  // read everything now: a corrupt file fails here, not half way through
    openvdb::GridPtrVecPtr metas = file.readAllGridMetadata();
    openvdb::GridBase::ConstPtr chosen;
    for (const auto& g : *metas) {
      if (request.gridName.empty() ? g->isType<openvdb::FloatGrid>() : g->getName() == request.gridName) {
        chosen = g;
        break;
      }
    }
    if (!chosen) {
      file.close();
      if (request.gridName.empty())
        throw Error(kExitModelError, shown + ": no float grid to " + request.verb + " (" + gridList(*metas) + "); " +
                                         request.user + " reads a FloatGrid such as frep sample writes");
      throw Error(kExitModelError, shown + ": no grid named '" + request.gridName + "' (" + request.nameSource + "); " +
                                       gridList(*metas));
    }
    if (!chosen->isType<openvdb::FloatGrid>()) {
      file.close();
      throw Error(kExitModelError, shown + ": grid '" + chosen->getName() + "' holds " + chosen->valueType() +
                                       " values; " + request.user + " needs a float grid (as frep sample writes)");
    }
    chosenName = chosen->getName();
    grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(chosenName));
    file.close();
  } catch (const openvdb::Exception& e) {
    throw ioError("cannot read VDB '" + shown + "': " + named(e.what()));
  } catch (const std::ios_base::failure& e) {
    throw ioError("cannot read VDB '" + shown + "': " + named(e.what()));
  } catch (const std::bad_alloc&) {
    throw ioError("cannot read VDB '" + shown + "': out of memory (sizes in the file are damaged, or it is too large)");
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {  // e.g. std::length_error from a damaged size: bad input, not a bug
    throw ioError("cannot read VDB '" + shown + "': damaged (" + named(e.what()) + ")");
  }
  if (!grid) throw ioError("cannot read VDB '" + shown + "': grid '" + chosenName + "' could not be loaded");
  return grid;
}

}  // namespace

CheckedGrid readCheckedFloatGrid(const std::string& path, const GridRequest& request) {
  openvdb::initialize();
  const std::string& shown = request.shown;
  CheckedGrid out;
  try {
    out.layout = checkVdbLayout(path);
  } catch (const Error& e) {
    std::string msg = e.what();
    if (shown != path)  // messages of the layout check name the path read
      for (size_t at = msg.find(path); at != std::string::npos; at = msg.find(path, at + shown.size()))
        msg.replace(at, path.size(), shown);
    throw Error(e.code, msg);
  }
  if (out.layout.sealMismatch)
    spdlog::warn(
        "{}: its {} no longer matches its contents (rewritten by another tool, or damaged): read as a "
        "foreign grid, checked as a level set only",
        shown, kGridChecksumKey);
  // OpenVDB parses the file in a child process (vdb_isolation.h) and writes the grid again, every
  // value stored; this process parses only that copy.
  const IsolatedOutput copy = runIsolated(shown, [&](const std::string& to) {
    const openvdb::FloatGrid::Ptr grid = parseFloatGrid(path, request, out.layout.bytes);
    grid->removeMeta(kGridChecksumKey);
    openvdb::io::File file(to);
    file.setCompression(openvdb::io::COMPRESS_NONE);
    file.setGridStatsMetadataEnabled(false);
    file.write(openvdb::GridCPtrVec{grid});
  });
  try {
    const VdbLayout copied = checkVdbLayout(copy.path());
    GridRequest again = request;
    again.gridName = "";
    out.grid = parseFloatGrid(copy.path(), again, copied.bytes);
  } catch (const Error& e) {
    throw Error(kExitInternal, "reading the copy of '" + shown + "' that OpenVDB wrote: " + e.what());
  }
  return out;
}

SampledVdb detail::openVdbReadSampled(const std::string& path, const std::string& gridName) {
  SampledVdb out;
  CheckedGrid checked = readCheckedFloatGrid(path, {path, gridName, "-o/--object", "mesh", "frep mesh"});
  const openvdb::FloatGrid::Ptr grid = checked.grid;
  out.gridName = grid->getName();
  out.contentHash = checked.layout.contentHash;
  // A fog volume (density: 0 outside, 1 inside) is meshed where its density crosses 0.5, as
  // frVolume reads one; anything else where its values change sign, negative inside.
  const bool fog = grid->getGridClass() == openvdb::GRID_FOG_VOLUME;
  const float fogIso = 0.5f;
  if (fog) {
    std::string where = "meshed where its density crosses 0.5";
    if (auto band = grid->getMetadata<openvdb::DoubleMetadata>("frep_band")) {
      char depth[64];  // the band is a float widened to double: 6 digits say it
      std::snprintf(depth, sizeof depth, "%g inside it, so this surface lies %g", band->value(), 0.5 * band->value());
      where += std::string(" (frep sample's fog ramps from 0 at the surface to 1 at ") + depth +
               " inside the model's; the model's own surface is in its --store sdf grid)";
    }
    spdlog::info("{}: grid '{}' is a fog volume: {}", path, out.gridName, where);
  } else if (grid->getGridClass() != openvdb::GRID_LEVEL_SET) {
    spdlog::warn("{}: grid '{}' is not a level set (class {}); meshing where its values change sign, negative inside",
                 path, out.gridName, openvdb::GridBase::gridClassToString(grid->getGridClass()));
  }
  // A foreign level set (no frep seal, or one that no longer matches) is checked as a level set:
  // finite values within its background's magnitude (OpenVDB's narrow band), else refused.
  const bool checkBand = !checked.layout.sealed && grid->getGridClass() == openvdb::GRID_LEVEL_SET;
  const float bandLimit = std::fabs(grid->background()) * (1 + 1e-5f);

  const openvdb::FloatTree& tree = grid->tree();
  // Leaf origins shifted to be >= 0 (multiples of 8, so the shift keeps them aligned).
  int64_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  size_t leafCount = 0;
  for (auto it = tree.cbeginLeaf(); it; ++it, ++leafCount) {
    const openvdb::Coord o = it->origin();
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min<int64_t>(lo[a], o[a]);
      hi[a] = std::max<int64_t>(hi[a], int64_t(o[a]) + kLeafDim);
    }
  }
  for (int a = 0; a < 3; ++a)
    if (hi[a] - lo[a] >= kMaxMeshGridPoints)
      throw Error(kExitModelError, path + ": grid '" + out.gridName + "' spans " + std::to_string(hi[a] - lo[a]) +
                                       " voxels along an axis; frep mesh handles up to " +
                                       std::to_string(kMaxMeshGridPoints - 1));
  SampleResult& s = out.samples;
  s.leaves.reserve(leafCount);
  std::unordered_set<uint64_t> leafIds;
  leafIds.reserve(leafCount * 2);
  for (auto it = tree.cbeginLeaf(); it; ++it) {
    const openvdb::Coord o = it->origin();
    LeafBlock b;
    b.origin = {int32_t(o[0] - lo[0]), int32_t(o[1] - lo[1]), int32_t(o[2] - lo[2])};
    b.active.fill(0);
    for (openvdb::Index n = 0; n < openvdb::Index(kLeafVoxels); ++n) {
      const float v = it->getValue(n);
      if (!std::isfinite(v) || (checkBand && std::fabs(v) > bandLimit)) {
        const openvdb::Coord c = it->offsetToGlobalCoord(n);
        throw ioError("cannot read VDB '" + path + "': grid '" + out.gridName + "' is not a valid " +
                      (checkBand ? "level set" : "grid") + ": voxel (" + std::to_string(c[0]) + ", " +
                      std::to_string(c[1]) + ", " + std::to_string(c[2]) + ") holds " + formatNumber(v) +
                      (checkBand ? ", beyond its background " + formatNumber(grid->background()) : "") +
                      " (the file is damaged)");
      }
      if (fog) {  // every value is the density itself (the exterior is 0, inactive)
        b.values[n] = v - fogIso;
        b.active[n >> 6] |= uint64_t(1) << (n & 63);
        continue;
      }
      b.values[n] = -v;  // exact: the stored value is -f
      if (it->isValueOn(n)) b.active[n >> 6] |= uint64_t(1) << (n & 63);
    }
    s.leaves.push_back(b);
    leafIds.insert(blockId(lo, o[0], o[1], o[2]));
  }
  // Sign tiles for the blocks next to leaves (their gradients at the band's edge).
  openvdb::FloatGrid::ConstAccessor acc = grid->getConstAccessor();
  std::unordered_set<uint64_t> tileIds;
  for (auto it = tree.cbeginLeaf(); it; ++it) {
    const openvdb::Coord o = it->origin();
    for (int n = 0; n < 27; ++n) {
      if (n == 13) continue;
      const openvdb::Coord b(o[0] + 8 * (n % 3 - 1), o[1] + 8 * (n / 3 % 3 - 1), o[2] + 8 * (n / 9 - 1));
      if (b[0] < lo[0] || b[1] < lo[1] || b[2] < lo[2]) continue;
      const uint64_t id = blockId(lo, b[0], b[1], b[2]);
      if (leafIds.count(id) || !tileIds.insert(id).second) continue;
      const float v = acc.getValue(b);
      const std::array<int32_t, 3> at = {int32_t(b[0] - lo[0]), int32_t(b[1] - lo[1]), int32_t(b[2] - lo[2])};
      if (fog) {  // a fog's crossing may reach into a tile: the tile's density as a leaf of values
        LeafBlock block;
        block.origin = at;
        block.values.fill(v - fogIso);
        block.active.fill(~uint64_t(0));
        s.leaves.push_back(block);
        continue;
      }
      s.tiles.push_back(Tile{at, kLeafDim, std::signbit(v) && !std::isnan(v)});
    }
  }
  sortByOrigin(s.leaves, s.tiles);
  for (const LeafBlock& b : s.leaves)  // a fog's tile blocks may lie past the last leaf
    for (int a = 0; a < 3; ++a) hi[a] = std::max<int64_t>(hi[a], lo[a] + b.origin[a] + kLeafDim);
  for (int a = 0; a < 3; ++a) {
    if (hi[a] - lo[a] >= kMaxMeshGridPoints)
      throw Error(kExitModelError, path + ": grid '" + out.gridName + "' spans too many voxels along an axis");
    s.grid.dims[a] = int32_t(hi[a] - lo[a]);
  }

  // The transform: a uniform scale and a translation becomes the GridSpec itself.
  const openvdb::math::Transform::Ptr xform = grid->transformPtr();
  bool scaleTranslate = false;
  if (xform->isLinear()) {
    const openvdb::Mat4d m = xform->baseMap()->getAffineMap()->getMat4();
    const double v = m(0, 0);
    scaleTranslate = v > 0 && m(1, 1) == v && m(2, 2) == v && m(0, 1) == 0 && m(0, 2) == 0 && m(1, 0) == 0 &&
                     m(1, 2) == 0 && m(2, 0) == 0 && m(2, 1) == 0;
    if (scaleTranslate) {
      s.grid.voxel = v;
      for (int a = 0; a < 3; ++a) s.grid.origin[a] = m(3, a) + double(lo[a]) * v;
      out.transformDescription = "voxel " + formatNumber(v) + ", index (0,0,0) at (" + formatNumber(m(3, 0)) + ", " +
                                 formatNumber(m(3, 1)) + ", " + formatNumber(m(3, 2)) + ")";
    }
  }
  if (!scaleTranslate) {
    s.grid.voxel = 1.0;
    for (int a = 0; a < 3; ++a) s.grid.origin[a] = double(lo[a]);
    out.transformDescription = "transform " + xform->mapType() + " (applied to the index-space mesh)";
    const bool mirror = xform->baseMap()->determinant(openvdb::Vec3d(0, 0, 0)) < 0;
    out.toWorld = [xform, mirror](Mesh& mesh) {
      for (size_t i = 0; i < mesh.positions.size(); ++i) {
        const openvdb::Vec3d p(mesh.positions[i][0], mesh.positions[i][1], mesh.positions[i][2]);
        openvdb::Vec3d n =
            xform->baseMap()->applyIJT(openvdb::Vec3d(mesh.normals[i][0], mesh.normals[i][1], mesh.normals[i][2]), p);
        const double len = n.length();
        if (len > 0 && std::isfinite(len)) n /= len;
        const openvdb::Vec3d w = xform->indexToWorld(p);
        for (int a = 0; a < 3; ++a) {
          mesh.positions[i][a] = w[a];
          if (len > 0 && std::isfinite(len)) mesh.normals[i][a] = n[a];
        }
      }
      if (mirror) {
        for (auto& t : mesh.triangles) std::swap(t[1], t[2]);  // the smallest index stays first
        std::sort(mesh.triangles.begin(), mesh.triangles.end());
      }
    };
  }
  int band = 0;
  if (auto meta = grid->getMetadata<openvdb::Int32Metadata>("frep_band_voxels")) band = meta->value();
  if (band < 1) band = int(std::lround(std::abs(double(grid->background())) / xform->voxelSize()[0]));
  s.bandVoxels = std::max(band, 1);
  return out;
}

}  // namespace frep::io
