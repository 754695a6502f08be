#include "frep/io/vdb_writer.h"

#include "frep/io/vdb_grid.h"
#include "frep/sampling/band_distance.h"
#include "frep/sampling/exact_band_distance.h"

#include <openvdb/openvdb.h>
#include <openvdb/io/Compression.h>
#include <openvdb/io/DelayedLoadMetadata.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/Prune.h>

#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <sstream>
#include <stdexcept>

#include "frep/io/error.h"
#include "sealed_vdb_file.h"
#include "vdb_backend.h"
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
// False when it lies entirely past the grid.
bool tileBox(const Tile& tile, const std::array<int32_t, 3>& extent, const openvdb::Coord& offset,
             openvdb::CoordBBox& box) {
  openvdb::Coord lo, hi;
  for (int a = 0; a < 3; ++a) {
    if (tile.origin[a] >= extent[a]) return false;
    lo[a] = tile.origin[a] + offset[a];
    hi[a] = std::min(tile.origin[a] + tile.size, extent[a]) - 1 + offset[a];
  }
  box = openvdb::CoordBBox(lo, hi);
  return true;
}

void addLeaf(openvdb::FloatGrid::Accessor& acc, const LeafBlock& block, const openvdb::Coord& offset) {
  const openvdb::Coord o = openvdb::Coord(block.origin[0], block.origin[1], block.origin[2]) + offset;
  if (((o.x() | o.y() | o.z()) & 7) == 0) {  // the block is one of OpenVDB's leaves (leafAlignedGrid)
    // The same voxel order (x, then y, then z) and mask words: every value and state replaced,
    // as the loop below sets them, without an accessor call a voxel.
    openvdb::FloatTree::LeafNodeType* leaf = acc.touchLeaf(o);
    float* values = leaf->buffer().data();
    for (int n = 0; n < kLeafVoxels; ++n) values[n] = -block.values[size_t(n)];  // negative inside
    openvdb::FloatTree::LeafNodeType::NodeMaskType mask;
    for (int w = 0; w < kLeafVoxels / 64; ++w) mask.getWord<uint64_t>(openvdb::Index(w)) = block.active[size_t(w)];
    leaf->setValueMask(mask);
    return;
  }
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

// The file openvdb::io::File::write would write (the same Archive::write, seekable), with every
// write checked (OpenVDB's own file writer ignores a failing stream: ENOSPC, EFBIG).
struct FileArchive : openvdb::io::Archive {
  void writeTo(std::ostream& os, const openvdb::GridCPtrVec& grids) const {
    write(os, grids, /*seekable=*/true);  // a failed write: writeSealedVdb names its error
  }
  // What write() writes for one grid, for a grid whose leaves were written out (SpillingGrid):
  // its metadata as it is (the statistics and file_delayed_load already in it: the archive
  // would compute them from the leaves' values), then its transform, topology and buffers.
  void writeWithoutValues(std::ostream& os, const openvdb::GridBase& grid) const {
    namespace io = openvdb::io;
    io::StreamMetadata::Ptr file = std::make_shared<io::StreamMetadata>();
    io::setStreamMetadataPtr(os, file, /*transfer=*/false);
    io::setDataCompression(os, compression());
    io::setWriteGridStatsMetadata(os, false);
    writeHeader(os, /*seekable=*/true);
    openvdb::MetaMap().writeMeta(os);
    const int32_t grids = 1;
    os.write(reinterpret_cast<const char*>(&grids), sizeof grids);
    const std::string name = grid.getName().empty() ? io::GridDescriptor::addSuffix("", 0) : grid.getName();
    io::GridDescriptor gd(name, grid.type(), grid.saveFloatAsHalf());
    io::StreamMetadata::Ptr perGrid = std::make_shared<io::StreamMetadata>(*file);
    perGrid->setHalfFloat(grid.saveFloatAsHalf());
    perGrid->gridMetadata() = static_cast<const openvdb::MetaMap&>(grid);
    io::setStreamMetadataPtr(os, perGrid, /*transfer=*/false);
    gd.writeHeader(os);
    const int64_t offsets = int64_t(os.tellp());
    gd.writeStreamPos(os);
    gd.setGridPos(os.tellp());
    setGridCompression(os, grid);
    grid.writeMeta(os);
    grid.writeTransform(os);
    grid.writeTopology(os);
    gd.setBlockPos(os.tellp());
    grid.writeBuffers(os);
    gd.setEndPos(os.tellp());
    os.seekp(offsets, std::ios_base::beg);
    gd.writeStreamPos(os);
    gd.seekToEnd(os);
    io::setStreamMetadataPtr(os, file, /*transfer=*/false);
  }
};

std::string hex(uint64_t v) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// The leaves of a grid written out as they become final (LevelSetBuilder with spillLeaves): each
// one's bytes as LeafNode::writeBuffers gives them, in a temporary file (tmpfile(): unlinked,
// in /tmp) in the order they finish, and in the tree a leaf with its value mask only (no
// values: ~100 bytes instead of ~2.2 KB). SpillingGrid writes the file's buffers section in the
// tree's order from it: the same bytes as the leaves held whole.
struct LeafSpill {
  std::FILE* file = nullptr;
  uint64_t size = 0;
  // A leaf's place in the file, and what the archive's delayed-load metadata says of it.
  struct Record {
    uint64_t offset;
    uint32_t bytes;
    int8_t mask;
    int64_t compressed;
  };
  std::map<std::array<int32_t, 3>, Record> at;  // by origin
  uint32_t compression = 0;  // the stream's, as Archive::setGridCompression sets it for a level set
  openvdb::io::StreamMetadata::Ptr streamMeta = std::make_shared<openvdb::io::StreamMetadata>();
  float background;
  explicit LeafSpill(float bg) : file(std::tmpfile()), background(bg) {
    if (!file) throw ioError(std::string("cannot create a temporary file for the finished leaves: ") + std::strerror(errno));
    compression = openvdb::io::Archive::hasBloscCompression() ? openvdb::io::COMPRESS_BLOSC : openvdb::io::COMPRESS_NONE;
  }
  ~LeafSpill() { std::fclose(file); }
  LeafSpill(const LeafSpill&) = delete;
  LeafSpill& operator=(const LeafSpill&) = delete;
  void put(const openvdb::FloatTree::LeafNodeType& leaf) {
    std::ostringstream os(std::ios_base::out | std::ios_base::binary);
    openvdb::io::setStreamMetadataPtr(os, streamMeta, /*transfer=*/false);
    openvdb::io::setDataCompression(os, compression);
    leaf.writeBuffers(os, /*toHalf=*/false);
    const std::string bytes = os.str();
    if (std::fwrite(bytes.data(), 1, bytes.size(), file) != bytes.size())
      throw ioError(std::string("cannot write the finished leaves' temporary file: ") + std::strerror(errno));
    const openvdb::Coord o = leaf.origin();
    const auto [mask, compressed] = delayedLoadEntry(leaf, background, compression);
    at[{o.x(), o.y(), o.z()}] = {size, uint32_t(bytes.size()), mask, compressed};
    size += bytes.size();
  }
  // What OpenVDB 10's archive records of a leaf in the grid's file_delayed_load metadata: the
  // mask compression's verdict and the size of the values' block (checked against its files).
  static std::pair<int8_t, int64_t> delayedLoadEntry(const openvdb::FloatTree::LeafNodeType& leaf, float background,
                                                     uint32_t compression) {
    using Mask = openvdb::FloatTree::LeafNodeType::NodeMaskType;
    const float* values = leaf.buffer().data();
    const openvdb::io::MaskCompress<float, Mask> verdict(leaf.valueMask(), Mask(), values, background);
    const size_t bytes = openvdb::io::writeCompressedValuesSize(values, leaf.SIZE, leaf.valueMask(),
                                                                uint8_t(verdict.metadata), false, compression);
    return {verdict.metadata, int64_t(bytes) + int64_t(sizeof(int64_t))};  // and the block's size field
  }
  void copy(const openvdb::Coord& o, std::ostream& os, std::vector<char>& buffer) const {
    const Record& r = at.at({o.x(), o.y(), o.z()});
    const uint64_t offset = r.offset;
    const uint32_t bytes = r.bytes;
    buffer.resize(bytes);
    if (std::fflush(file) != 0 || ::pread(::fileno(file), buffer.data(), bytes, off_t(offset)) != ssize_t(bytes))
      throw openvdb::IoError(std::string("cannot read back a finished leaf: ") + std::strerror(errno ? errno : EIO));
    os.write(buffer.data(), std::streamsize(bytes));
  }
};

struct SpillingGrid final : openvdb::FloatGrid {
  explicit SpillingGrid(float background) : openvdb::FloatGrid(background) {}
  std::shared_ptr<LeafSpill> spill;
  // Tree::writeBuffers' order (the root's table, then each node's children in offset order).
  void writeBuffers(std::ostream& os) const override {
    if (!spill || spill->at.empty()) return openvdb::FloatGrid::writeBuffers(os);
    std::vector<char> buffer;
    for (auto upper = tree().root().cbeginChildOn(); upper; ++upper)
      for (auto lower = upper->cbeginChildOn(); lower; ++lower)
        for (auto leaf = lower->cbeginChildOn(); leaf; ++leaf) {
          if (leaf->isAllocated()) leaf->writeBuffers(os, /*toHalf=*/false);
          else spill->copy(leaf->origin(), os, buffer);
        }
  }
};

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
  bool eager = true;  // prune final leaves as they come (addLeaves)
  std::shared_ptr<LeafSpill> spill;  // and write the others out (LevelSetBuilder's spillLeaves)
  int64_t finalBelow = INT64_MIN;  // world x below which every leaf was pruned if inactive
  int64_t filledBelow = INT64_MIN;  // world x below which every tile added is filled in
  std::vector<std::pair<openvdb::CoordBBox, float>> pending;  // the rest of the tiles, in order
  GridAssembly(const GridSpec& lattice, int band)
      : g(lattice),
        bandVoxels(band),
        background(float(band * lattice.voxel)),
        extent{(lattice.dims[0] + 7) & ~7, (lattice.dims[1] + 7) & ~7, (lattice.dims[2] + 7) & ~7},
        offset(latticeOffset(lattice)),
        grid((openvdb::initialize(), std::make_shared<SpillingGrid>(background))),
        acc(grid->getAccessor()) {}
  // Eager, a tile is filled in only up to the x the leaves have reached (fillTo), the rest as
  // the leaves come: a large tile's misaligned faces would otherwise fill dense leaves along its
  // whole length at once (151 MB at once at 1024^3). Filling a box in pieces cut along x sets
  // the same voxels, in the same order as the other tiles; where it leaves other nodes than one
  // fill, they are inactive and uniform, and pruneLevelSet makes them the same tiles.
  void addTiles(const std::vector<Tile>& tiles) {
    for (const Tile& t : tiles) {
      openvdb::CoordBBox box;
      if (!tileBox(t, extent, offset, box)) continue;
      const float value = t.inside ? -background : background;
      if (!eager) {
        grid->tree().fill(box, value, false);
        continue;
      }
      if (box.min().x() < filledBelow) {
        openvdb::CoordBBox now = box;
        now.max().x() = int32_t(std::min<int64_t>(box.max().x(), filledBelow - 1));
        grid->tree().fill(now, value, false);
        if (box.max().x() < filledBelow) continue;
        box.min().x() = int32_t(filledBelow);
      }
      pending.emplace_back(box, value);
    }
  }
  // The pending tiles filled in below world x (a multiple of a leaf's size: no leaf is cut).
  void fillTo(int64_t x) {
    if (x <= filledBelow) return;
    acc.clear();
    size_t kept = 0;
    for (auto& [box, value] : pending) {
      openvdb::CoordBBox now = box;
      if (now.min().x() < x) {
        now.max().x() = int32_t(std::min<int64_t>(now.max().x(), x - 1));
        grid->tree().fill(now, value, false);
        if (box.max().x() < x) continue;
        box.min().x() = int32_t(x);
      }
      pending[kept++] = {box, value};
    }
    pending.resize(kept);
    filledBelow = x;
  }
  // The pending tiles filled in below world x (a multiple of 8) and what is final there pruned,
  // one leaf of x at a time: the dense leaves a tile's misaligned faces fill in live for one
  // step (a gap of tiles without leaves, or those past the last leaf, filled at once: 0.1 GB).
  void fillAndPrune(int64_t x) {
    while (filledBelow < x) {
      int64_t from = filledBelow;
      if (from == INT64_MIN) {  // nothing filled yet: from the first pending tile
        from = x;
        for (const auto& p : pending) from = std::min<int64_t>(from, p.first.min().x());
        from &= ~int64_t(7);
      }
      const int64_t step = std::min(x, from + 8);
      fillTo(step);
      pruneFinalLeaves(step);
    }
  }
  // Each call's leaves at or past (in x) every earlier call's (the farm's slabs, a sample's
  // sorted leaves; tiles at or past the leaves added: LevelSetBuilder::addTiles), so what lies
  // before a call's leaves is final: the tiles are filled in and the leaves without an active
  // voxel pruned there, as pruneLevelSet will at the end (a tile of the sign of its first value;
  // the levels above see the same tiles in finish()). Else the leaves that misaligned tiles fill
  // in (the sampler's 8-grid is offset from OpenVDB's by the lattice's origin) lived until the
  // end: ~0.9 GB at 1024^3.
  void addLeaves(const std::vector<LeafBlock>& leaves) {
    if (!eager || leaves.empty()) {
      for (const LeafBlock& b : leaves) addLeaf(acc, b, offset);
      return;
    }
    int64_t lo = INT64_MAX, last = INT64_MIN;
    for (const LeafBlock& b : leaves) {
      lo = std::min(lo, int64_t(b.origin[0]) + offset[0]);
      last = std::max(last, int64_t(b.origin[0]) + offset[0]);
    }
    if (lo < finalBelow)
      throw std::logic_error("GridAssembly: a leaf at x " + std::to_string(lo - offset[0]) + " after leaves past it");
    fillAndPrune(lo & ~int64_t(7));                       // what lies before these leaves is final
    fillTo((last + kLeafDim + 7) & ~int64_t(7));          // the tiles under them
    for (const LeafBlock& b : leaves) addLeaf(acc, b, offset);
    pruneFinalLeaves(last);  // later calls' leaves lie at or past it
  }
  // Prunes the inactive leaves that end at or below world index x (nothing will be added there).
  void pruneFinalLeaves(int64_t x) {
    if (x < finalBelow + openvdb::FloatTree::LeafNodeType::DIM) return;  // no new column of leaves
    acc.clear();  // it may cache a leaf pruned below
    for (auto upper = grid->tree().root().beginChildOn(); upper; ++upper) {
      if (upper->origin().x() >= x) continue;
      for (auto lower = upper->beginChildOn(); lower; ++lower) {
        const int64_t lo = lower->origin().x();
        if (lo >= x || lo + lower->DIM <= finalBelow) continue;  // none of its leaves newly final
        for (auto leaf = lower->beginChildOn(); leaf; ++leaf) {
          if (int64_t(leaf->origin().x()) + leaf->DIM > x) continue;
          if (leaf->isInactive()) {
            lower->addTile(leaf.pos(), openvdb::math::isNegative(leaf->getFirstValue()) ? -background : background,
                           false);
          } else if (spill && leaf->isAllocated()) {
            spill->put(*leaf);
            auto* stub = new openvdb::FloatTree::LeafNodeType(openvdb::PartialCreate(), leaf->origin(), 0.0f, false);
            stub->setValueMask(leaf->getValueMask());
            lower->addLeaf(stub);  // deletes the leaf
          }
        }
      }
    }
    finalBelow = x;
  }
  openvdb::FloatGrid::Ptr finish() {
    static_cast<SpillingGrid&>(*grid).spill = spill;
    if (eager) {
      int64_t end = INT64_MIN;
      for (const auto& p : pending) end = std::max(end, int64_t(p.first.max().x()) + 1);
      fillAndPrune((end + 7) & ~int64_t(7));
    }
    fillTo(INT64_MAX);
    acc.clear();
    openvdb::tools::pruneLevelSet(grid->tree());  // canonical tree: the same whatever the brick layout
    grid->setTransform(openvdb::math::Transform::createLinearTransform(g.voxel));
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    return std::move(grid);
  }
};

}  // namespace

openvdb::FloatGrid::Ptr levelSetGrid(const SampleResult& result) {
  GridAssembly tree(result.grid, result.bandVoxels);
  tree.eager = std::is_sorted(result.leaves.begin(), result.leaves.end(),
                              [](const LeafBlock& a, const LeafBlock& b) { return a.origin[0] < b.origin[0]; });
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

namespace {

// A finished levelSetGrid of the lattice `g` to the file: the signed distance unless raw, the
// metadata, the checksum, then every byte written and checked.
void writeGrid(const std::string& path, openvdb::FloatGrid::Ptr grid, const GridSpec& g, int bandVoxels,
               const VdbMetadata& meta) {
  const auto* spilling = dynamic_cast<const SpillingGrid*>(grid.get());
  const LeafSpill* spill = spilling && spilling->spill && !spilling->spill->at.empty() ? spilling->spill.get() : nullptr;
  if (spill && (meta.store == VdbStore::Fog || (meta.store == VdbStore::Sdf && !meta.distanceValues)))
    throw std::logic_error("writeGrid: the leaves went to a file; the grid can be written only as stored");
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
    grid->insertMeta("frep_distance", openvdb::StringMetadata(meta.exactDistance ? exactBandDistanceBound()
                                                                                 : bandDistanceBound()));

  try {
    grid->insertMeta(kGridChecksumKey, openvdb::StringMetadata(std::string(kChecksumDigits, '0')));  // sealed below
    FileArchive archive;
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
    if (spill) {
      // The statistics the archive adds, taken here: the leaves written out hold no values, so
      // memUsage() misses SIZE floats for each (the tree held whole would count them).
      archive.setGridStatsMetadataEnabled(false);
      grid->addStatsMetadata();
      const int64_t values = int64_t(openvdb::FloatTree::LeafNodeType::SIZE * sizeof(float));
      const int64_t memory = int64_t(grid->memUsage()) + values * int64_t(spill->at.size());
      grid->removeMeta(openvdb::GridBase::META_FILE_MEM_BYTES);
      grid->insertMeta(openvdb::GridBase::META_FILE_MEM_BYTES, openvdb::Int64Metadata(memory));
      grid->insertMeta(openvdb::GridBase::META_FILE_COMPRESSION,
                       openvdb::StringMetadata(openvdb::io::compressionToString(spill->compression)));
      // The delayed-load metadata too: the archive would read every leaf's values for it.
      openvdb::io::DelayedLoadMetadata delayed;
      const size_t leaves = size_t(grid->tree().leafCount());
      delayed.resizeMask(leaves);
      delayed.resizeCompressedSize(leaves);
      size_t i = 0;
      for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf, ++i) {
        const openvdb::Coord o = leaf->origin();
        const auto [mask, compressed] = leaf->isAllocated()
                                            ? LeafSpill::delayedLoadEntry(*leaf, background, spill->compression)
                                            : std::pair<int8_t, int64_t>{spill->at.at({o.x(), o.y(), o.z()}).mask,
                                                                         spill->at.at({o.x(), o.y(), o.z()}).compressed};
        delayed.setMask(i, mask);
        delayed.setCompressedSize(i, compressed);
      }
      grid->insertMeta(openvdb::GridBase::META_FILE_DELAYED_LOAD, delayed);
    }
    // Straight to the file and sealed there: the serialised grid (62 MB at 1024^3) is not held
    // in memory on top of the tree.
    detail::writeSealedVdb(path, [&](std::ostream& os) {
      if (spill) archive.writeWithoutValues(os, *grid);
      else archive.writeTo(os, openvdb::GridCPtrVec{grid});
    });
  } catch (const openvdb::Exception& e) {
    throw ioError("cannot write VDB '" + path + "': " + e.what());
  }
}

}  // namespace

namespace detail {

void openVdbWriteLevelSet(const std::string& path, const SampleResult& result, const VdbMetadata& meta) {
  writeGrid(path, levelSetGrid(result), result.grid, result.bandVoxels, meta);
}

namespace {

class OpenVdbLevelSetTree final : public LevelSetTree {
 public:
  OpenVdbLevelSetTree(const GridSpec& grid, int bandVoxels, bool spillLeaves)
      : tree_(std::make_unique<GridAssembly>(grid, bandVoxels)) {
    if (spillLeaves) tree_->spill = std::make_shared<LeafSpill>(tree_->background);
  }
  void addTiles(const std::vector<Tile>& tiles) override { tree_->addTiles(tiles); }
  void addLeaves(const std::vector<LeafBlock>& leaves) override { tree_->addLeaves(leaves); }
  uint64_t leavesWrittenOut() const override { return tree_->spill ? tree_->spill->at.size() : 0; }
  void write(const std::string& path, const VdbMetadata& meta) override {
    const GridSpec g = tree_->g;
    const int bandVoxels = tree_->bandVoxels;
    openvdb::FloatGrid::Ptr grid = tree_->finish();
    tree_.reset();
    writeGrid(path, std::move(grid), g, bandVoxels, meta);
  }

 private:
  std::unique_ptr<GridAssembly> tree_;
};

}  // namespace

std::unique_ptr<LevelSetTree> openVdbLevelSetTree(const GridSpec& grid, int bandVoxels, bool spillLeaves) {
  return std::make_unique<OpenVdbLevelSetTree>(grid, bandVoxels, spillLeaves);
}

}  // namespace detail
}  // namespace frep::io
