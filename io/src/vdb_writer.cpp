#include "frep/io/vdb_writer.h"

#include "frep/io/vdb_grid.h"
#include "frep/sampling/band_distance.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/Prune.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "frep/io/error.h"
#include "vdb_checksum.h"

#ifndef FREP_VERSION
#define FREP_VERSION "unknown"
#endif

namespace frep::io {
namespace {

// The sampler's index (i, j, k) is the world lattice's (i, j, k) + offset: its origin is a whole
// number of voxels from the world origin (makeGrid), so the grid's transform is a pure scale.
openvdb::Coord latticeOffset(const GridSpec& g) {
  return openvdb::Coord(int32_t(std::llround(g.origin[0] / g.voxel)), int32_t(std::llround(g.origin[1] / g.voxel)),
                        int32_t(std::llround(g.origin[2] / g.voxel)));
}

// A sampler tile, clipped to the grid's leaf-aligned extent (a brick's root cube may reach past
// it) so that the tree, once pruned, does not depend on how the job was split into bricks.
void addTile(openvdb::FloatTree& tree, const Tile& tile, float value, const std::array<int32_t, 3>& extent,
             const openvdb::Coord& offset) {
  openvdb::Coord lo, hi;
  for (int a = 0; a < 3; ++a) {
    if (tile.origin[a] >= extent[a]) return;  // entirely past the grid
    lo[a] = tile.origin[a] + offset[a];
    hi[a] = std::min(tile.origin[a] + tile.size, extent[a]) - 1 + offset[a];
  }
  tree.fill(openvdb::CoordBBox(lo, hi), value, false);
}

void addLeaf(openvdb::FloatGrid::Accessor& acc, const LeafBlock& block, const openvdb::Coord& offset) {
  const openvdb::Coord o = openvdb::Coord(block.origin[0], block.origin[1], block.origin[2]) + offset;
  for (int x = 0; x < kLeafDim; ++x)
    for (int y = 0; y < kLeafDim; ++y)
      for (int z = 0; z < kLeafDim; ++z) {
        const int n = leafOffset(x, y, z);
        const float value = -block.values[size_t(n)];  // level sets are negative inside
        const openvdb::Coord c = o.offsetBy(x, y, z);
        if (block.isActive(n)) acc.setValueOn(c, value);
        else acc.setValueOff(c, value);
      }
}

// The bytes openvdb::io::File::write would put in the file (the same Archive::write, seekable),
// built in memory: OpenVDB's own file writer ignores a failing stream (ENOSPC, EFBIG).
struct MemoryArchive : openvdb::io::Archive {
  std::string bytes(const openvdb::GridCPtrVec& grids) const {
    std::ostringstream os(std::ios_base::out | std::ios_base::binary);
    write(os, grids, /*seekable=*/true);
    if (!os) throw openvdb::IoError("cannot serialise the grid");
    return os.str();
  }
};

// The checksum entry's placeholder digits replaced by the file's checksum, and the header's UUID
// by the one the checksum gives (vdb_checksum.h). The entry is found with its length prefixes,
// which hold NUL bytes no metadata text from argv has.
void sealChecksum(std::string& bytes) {
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::string key = kGridChecksumKey;
  const std::string entry = u32(uint32_t(key.size())) + key + u32(6) + "string" + u32(uint32_t(kChecksumDigits)) +
                            std::string(kChecksumDigits, '0');
  const size_t at = bytes.find(entry);
  if (at == std::string::npos) throw openvdb::IoError("the checksum entry is missing from the serialised grid");
  const size_t digits = at + entry.size() - kChecksumDigits;
  const std::string checksum = vdbChecksum(bytes, digits);
  bytes.replace(digits, kChecksumDigits, checksum);
  // OpenVDB stamps a random UUID into every file header; frep's comes from the seal (the same grid
  // gives the same bytes: farm runs are compared byte for byte), which tells damage in place from
  // a rewrite by another tool (vdb_checksum.h).
  const bool looksLikeUuid = bytes.size() > kVdbUuidAt + kVdbUuidLength && bytes[kVdbUuidAt + 8] == '-' &&
                             bytes[kVdbUuidAt + 13] == '-' && bytes[kVdbUuidAt + 18] == '-' &&
                             bytes[kVdbUuidAt + 23] == '-';
  if (!looksLikeUuid) throw openvdb::IoError("the serialised header has no UUID where OpenVDB 10 puts it");
  bytes.replace(kVdbUuidAt, kVdbUuidLength, vdbUuidForChecksum(checksum));
}

// Every byte handed to the kernel and checked, then fsync and the size read back: a full disk
// fails here (exit 3) and AtomicOutput never renames a truncated file into place.
void writeAllOrThrow(const std::string& path, const std::string& bytes) {
  auto fail = [&](const char* what) {
    throw ioError("cannot write VDB '" + path + "': " + what + ": " + std::strerror(errno));
  };
  int fd = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) fail("open");
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = ENOSPC;
      int err = errno;
      ::close(fd);
      errno = err;
      fail("write");
    }
    done += size_t(n);
  }
  struct stat st;
  if (::fsync(fd) != 0 || ::fstat(fd, &st) != 0) {
    int err = errno;
    ::close(fd);
    errno = err;
    fail("fsync");
  }
  if (::close(fd) != 0) fail("close");
  if (uint64_t(st.st_size) != bytes.size()) {
    errno = EIO;
    fail(("size " + std::to_string(st.st_size) + " instead of " + std::to_string(bytes.size())).c_str());
  }
}

std::string hex(uint64_t v) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// The level set grid as the sampler's output comes in: tiles first, then leaves, then finished
// (pruned to the canonical tree, transform and class set). levelSetGrid and LevelSetBuilder.
struct GridAssembly {
  GridSpec g;
  int bandVoxels;
  float background;
  std::array<int32_t, 3> extent;
  openvdb::Coord offset;
  openvdb::FloatGrid::Ptr grid;
  openvdb::FloatGrid::Accessor acc;
  GridAssembly(const GridSpec& lattice, int band)
      : g(lattice),
        bandVoxels(band),
        background(float(band * lattice.voxel)),
        extent{(lattice.dims[0] + 7) & ~7, (lattice.dims[1] + 7) & ~7, (lattice.dims[2] + 7) & ~7},
        offset(latticeOffset(lattice)),
        grid((openvdb::initialize(), openvdb::FloatGrid::create(background))),
        acc(grid->getAccessor()) {}
  void addTiles(const std::vector<Tile>& tiles) {
    for (const Tile& t : tiles) addTile(grid->tree(), t, t.inside ? -background : background, extent, offset);
  }
  void addLeaves(const std::vector<LeafBlock>& leaves) {
    for (const LeafBlock& b : leaves) addLeaf(acc, b, offset);
  }
  openvdb::FloatGrid::Ptr finish() {
    acc.clear();
    openvdb::tools::pruneLevelSet(grid->tree());  // canonical tree: the same whatever the brick layout
    grid->setTransform(openvdb::math::Transform::createLinearTransform(g.voxel));
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    return std::move(grid);
  }
};

}  // namespace

struct LevelSetBuilder::Tree : GridAssembly {
  using GridAssembly::GridAssembly;
};

openvdb::FloatGrid::Ptr levelSetGrid(const SampleResult& result) {
  GridAssembly tree(result.grid, result.bandVoxels);
  tree.addTiles(result.tiles);
  tree.addLeaves(result.leaves);
  return tree.finish();
}

openvdb::FloatGrid::Ptr signedDistanceGrid(const openvdb::FloatGrid& raw, int bandVoxels) {
  // Meshes the zero set of -f (linear along the lattice's edges) and takes the exact distance to
  // that mesh in a band of bandVoxels either side, on the same transform: a pure function of the
  // merged grid, so as deterministic as it is (TBB only splits a min over triangles).
  const float band = float(bandVoxels);
  openvdb::FloatGrid::Ptr sdf = openvdb::tools::levelSetRebuild(raw, 0.0f, band, band);
  // meshToVolume decides inside/outside by its own flood fill, which can flip a voxel next to
  // a concave corner of the mesh (seen: 8 voxels of a slot's ends, 0.02 outside where f was
  // +0.03). The sampled signs are certified: every voxel of the rebuilt leaves takes raw's sign
  // (raw's value there, tile or background included), keeping its distance to the mesh.
  openvdb::FloatGrid::ConstAccessor signs = raw.getConstAccessor();
  for (auto leaf = sdf->tree().beginLeaf(); leaf; ++leaf) {
    for (auto v = leaf->beginValueAll(); v; ++v) {
      const float want = signs.getValue(v.getCoord());
      const float got = v.getValue();
      if (want != 0 && (want < 0) != (got < 0)) v.setValue(got == 0 ? std::copysign(0.0f, want) : -got);
    }
  }
  sdf->setGridClass(openvdb::GRID_LEVEL_SET);
  openvdb::tools::pruneLevelSet(sdf->tree());
  return sdf;
}

namespace {

const char* signDescription(VdbStore store) {
  switch (store) {
    case VdbStore::Raw: return "value = -f";
    case VdbStore::Fog: return "value = density: 1 inside, 0 outside, a linear ramp across the inner band";
    case VdbStore::Sdf: break;
  }
  return "value = signed distance to the surface f = 0, negative inside, world units";
}

}  // namespace

const char* storeName(VdbStore store) {
  switch (store) {
    case VdbStore::Raw: return "raw";
    case VdbStore::Fog: return "fog";
    case VdbStore::Sdf: break;
  }
  return "sdf";
}

namespace {

// A finished levelSetGrid of the lattice `g` to the file: the signed distance unless raw, the
// metadata, the checksum, then every byte written and checked.
void writeGrid(const std::string& path, openvdb::FloatGrid::Ptr grid, const GridSpec& g, int bandVoxels,
               const VdbMetadata& meta) {
  if (meta.store != VdbStore::Raw && !meta.distanceValues) grid = signedDistanceGrid(*grid, bandVoxels);
  if (meta.store == VdbStore::Fog) openvdb::tools::sdfToFogVolume(*grid);  // class fog volume
  const float background = float(bandVoxels * g.voxel);
  const openvdb::Coord offset = latticeOffset(g);
  const openvdb::Coord last = offset + openvdb::Coord(g.dims[0] - 1, g.dims[1] - 1, g.dims[2] - 1);
  // Blender's volume import looks for a grid named "density".
  grid->setName(meta.store == VdbStore::Fog ? "density" : meta.gridName);
  grid->insertMeta("frep_sign", openvdb::StringMetadata(signDescription(meta.store)));
  grid->insertMeta("frep_store", openvdb::StringMetadata(storeName(meta.store)));
  grid->insertMeta("frep_operation", openvdb::StringMetadata("sample"));
  grid->insertMeta("frep_model_hash", openvdb::StringMetadata(hex(meta.sourceHash)));
  grid->insertMeta("frep_source", openvdb::StringMetadata(meta.source));
  grid->insertMeta("frep_object", openvdb::StringMetadata(meta.gridName));
  grid->insertMeta("frep_job", openvdb::StringMetadata(meta.job));
  grid->insertMeta("frep_units", openvdb::StringMetadata("model units (the .hf file's coordinates)"));
  grid->insertMeta("frep_voxel", openvdb::DoubleMetadata(g.voxel));
  grid->insertMeta("frep_box_index_min", openvdb::Vec3IMetadata(openvdb::Vec3i(offset.asVec3i())));
  grid->insertMeta("frep_box_index_max", openvdb::Vec3IMetadata(openvdb::Vec3i(last.asVec3i())));
  grid->insertMeta("frep_box_min", openvdb::Vec3DMetadata(grid->indexToWorld(offset)));
  grid->insertMeta("frep_box_max", openvdb::Vec3DMetadata(grid->indexToWorld(last)));
  grid->insertMeta("frep_band_voxels", openvdb::Int32Metadata(bandVoxels));
  grid->insertMeta("frep_band", openvdb::DoubleMetadata(double(background)));
  grid->insertMeta("frep_iso", openvdb::DoubleMetadata(meta.iso));
  grid->insertMeta("frep_params", openvdb::StringMetadata(meta.params));
  grid->insertMeta("frep_version", openvdb::StringMetadata(FREP_VERSION));
  if (meta.store != VdbStore::Raw && meta.distanceValues)
    grid->insertMeta("frep_distance", openvdb::StringMetadata(bandDistanceBound()));

  try {
    grid->insertMeta(kGridChecksumKey, openvdb::StringMetadata(std::string(kChecksumDigits, '0')));  // sealed below
    MemoryArchive archive;
    // Every voxel's value is stored, not only the active ones (no COMPRESS_ACTIVE_MASK): with
    // the mask, a leaf's inactive values are rebuilt as +-background when the leaf is loaded,
    // and under OpenVDB's delayed loading (its default for files) the load reads the background
    // through a pointer to the root node of the tree the file was read into. The CSG tools
    // (tools::csgUnion etc., vdb_tool -union) steal leaves from the second grid and then
    // destroy it, so those leaves load later through a dangling pointer: garbage inactive
    // values, a union 6-18% too large (tests/tools/vdb_real_tools.py, both orders). Blosc
    // packs the repeated +-background values: about 23% more bytes.
    uint32_t compression = openvdb::io::COMPRESS_NONE;
    if (openvdb::io::Archive::hasBloscCompression()) compression |= openvdb::io::COMPRESS_BLOSC;
    else compression |= openvdb::io::COMPRESS_ZIP;
    archive.setCompression(compression);
    std::string bytes = archive.bytes(openvdb::GridCPtrVec{grid});
    sealChecksum(bytes);
    writeAllOrThrow(path, bytes);
  } catch (const openvdb::Exception& e) {
    throw ioError("cannot write VDB '" + path + "': " + e.what());
  }
}

}  // namespace

void writeLevelSet(const std::string& path, const SampleResult& result, const VdbMetadata& meta) {
  writeGrid(path, levelSetGrid(result), result.grid, result.bandVoxels, meta);
}

LevelSetBuilder::LevelSetBuilder(const GridSpec& grid, int bandVoxels)
    : tree_(std::make_unique<Tree>(grid, bandVoxels)) {}

LevelSetBuilder::~LevelSetBuilder() = default;

void LevelSetBuilder::addTiles(const std::vector<Tile>& tiles) {
  if (!tree_) throw std::logic_error("LevelSetBuilder: tiles after write");
  // A tile reaches only towards +x from its origin: one at or past the end in x of every leaf
  // added so far covers none of them (the farm hands over x-slab by x-slab), and the tree is
  // then the one all the tiles first would give.
  for (const Tile& t : tiles)
    if (leaves_ && t.origin[0] < leavesEndX_)
      throw std::logic_error("LevelSetBuilder: a tile at x " + std::to_string(t.origin[0]) +
                             " after leaves up to x " + std::to_string(leavesEndX_) + " it may cover");
  tree_->addTiles(tiles);
}

void LevelSetBuilder::addLeaves(const std::vector<LeafBlock>& leaves) {
  if (!tree_) throw std::logic_error("LevelSetBuilder: leaves after write");
  tree_->addLeaves(leaves);
  for (const LeafBlock& l : leaves) leavesEndX_ = std::max(leavesEndX_, int64_t(l.origin[0]) + kLeafDim);
  leaves_ += leaves.size();
}

void LevelSetBuilder::write(const std::string& path, const VdbMetadata& meta) {
  if (!tree_) throw std::logic_error("LevelSetBuilder: written twice");
  const GridSpec g = tree_->g;
  const int bandVoxels = tree_->bandVoxels;
  openvdb::FloatGrid::Ptr grid = tree_->finish();
  tree_.reset();
  writeGrid(path, std::move(grid), g, bandVoxels, meta);
}

}  // namespace frep::io
