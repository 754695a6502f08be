#include "vdb_writer.h"

#include <openvdb/openvdb.h>

#include <cstdio>

#include "exit_codes.h"

#ifndef FREP_VERSION
#define FREP_VERSION "unknown"
#endif

namespace frep::cli {
namespace {

// OpenVDB's Tree4<float, 5, 4, 3> stores tiles of these edge lengths at levels 1, 2, 3.
constexpr int32_t kTileEdge[4] = {1, 8, 128, 4096};

// A sampler tile (power-of-two cube, aligned to its size) as the fewest VDB tiles.
void addTile(openvdb::FloatTree& tree, const Tile& tile, float value) {
  int level = 3;
  while (kTileEdge[level] > tile.size) --level;
  const int32_t step = kTileEdge[level];
  for (int32_t i = 0; i < tile.size; i += step)
    for (int32_t j = 0; j < tile.size; j += step)
      for (int32_t k = 0; k < tile.size; k += step)
        tree.addTile(openvdb::Index(level),
                     openvdb::Coord(tile.origin[0] + i, tile.origin[1] + j, tile.origin[2] + k), value, false);
}

void addLeaf(openvdb::FloatTree& tree, const LeafBlock& block) {
  auto* leaf = tree.touchLeaf(openvdb::Coord(block.origin[0], block.origin[1], block.origin[2]));
  for (int n = 0; n < kLeafVoxels; ++n) {
    const float value = -block.values[size_t(n)];  // level sets are negative inside
    if (block.isActive(n)) leaf->setValueOn(openvdb::Index(n), value);
    else leaf->setValueOff(openvdb::Index(n), value);
  }
}

std::string hex(uint64_t v) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

}  // namespace

void writeLevelSet(const std::string& path, const SampleResult& result, const VdbMetadata& meta) {
  openvdb::initialize();
  const GridSpec& g = result.grid;
  const float background = float(result.bandVoxels * g.voxel);
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(background);
  openvdb::FloatTree& tree = grid->tree();
  for (const Tile& t : result.tiles) addTile(tree, t, t.inside ? -background : background);
  for (const LeafBlock& b : result.leaves) addLeaf(tree, b);

  openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(g.voxel);
  xform->postTranslate(openvdb::Vec3d(g.origin[0], g.origin[1], g.origin[2]));
  grid->setTransform(xform);
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  grid->setName(meta.gridName);
  grid->insertMeta("frep_sign", openvdb::StringMetadata("value = -f"));
  grid->insertMeta("frep_operation", openvdb::StringMetadata("sample"));
  grid->insertMeta("frep_model_hash", openvdb::StringMetadata(hex(meta.sourceHash)));
  grid->insertMeta("frep_object", openvdb::StringMetadata(meta.gridName));
  grid->insertMeta("frep_command", openvdb::StringMetadata(meta.commandLine));
  grid->insertMeta("frep_band_voxels", openvdb::Int32Metadata(result.bandVoxels));
  grid->insertMeta("frep_band", openvdb::DoubleMetadata(double(background)));
  grid->insertMeta("frep_iso", openvdb::DoubleMetadata(meta.iso));
  grid->insertMeta("frep_params", openvdb::StringMetadata(meta.params));
  grid->insertMeta("frep_version", openvdb::StringMetadata(FREP_VERSION));

  try {
    openvdb::io::File file(path);
    uint32_t compression = openvdb::io::COMPRESS_ACTIVE_MASK;
    if (openvdb::io::Archive::hasBloscCompression()) compression |= openvdb::io::COMPRESS_BLOSC;
    file.setCompression(compression);
    file.write(openvdb::GridCPtrVec{grid});
    file.close();
  } catch (const openvdb::Exception& e) {
    throw ioError("cannot write VDB '" + path + "': " + e.what());
  }
}

}  // namespace frep::cli
