// The public .vdb functions, forwarded to the OpenVDB code wherever it is (vdb_backend.h): this
// file includes no OpenVDB header, so a program that never touches a .vdb never loads OpenVDB.
#include <algorithm>
#include <stdexcept>

#include "frep/io/geometry_files.h"
#include "frep/io/vdb_reader.h"
#include "frep/io/vdb_writer.h"
#include "vdb_backend.h"

namespace frep::io {

const char* storeName(VdbStore store) {
  switch (store) {
    case VdbStore::Raw:
      return "raw";
    case VdbStore::Fog:
      return "fog";
    case VdbStore::Sdf:
      break;
  }
  return "sdf";
}

SampledVdb readSampledVdb(const std::string& path, const std::string& gridName) {
  return detail::vdbBackend().readSampledVdb(path, gridName);
}

void writeLevelSet(const std::string& path, const SampleResult& result, const VdbMetadata& meta) {
  detail::vdbBackend().writeLevelSet(path, result, meta);
}

std::shared_ptr<const DistanceField> readVolumeField(const std::string& path, const std::string& bytes,
                                                     const std::string& grid, uint64_t fileHash) {
  return detail::vdbBackend().readVolumeField(path, bytes, grid, fileHash);
}

LevelSetBuilder::LevelSetBuilder(const GridSpec& grid, int bandVoxels, bool spillLeaves)
    : tree_(detail::vdbBackend().newLevelSetTree(grid, bandVoxels, spillLeaves)) {}

LevelSetBuilder::~LevelSetBuilder() = default;

uint64_t LevelSetBuilder::leavesWrittenOut() const { return tree_ ? tree_->leavesWrittenOut() : 0; }

void LevelSetBuilder::addTiles(const std::vector<Tile>& tiles) {
  if (!tree_) throw std::logic_error("LevelSetBuilder: tiles after write");
  // A tile reaches only towards +x from its origin: one at or past the end in x of every leaf
  // added so far covers none of them (the farm hands over x-slab by x-slab), and the tree is
  // then the one all the tiles first would give.
  for (const Tile& t : tiles)
    if (leaves_ && t.origin[0] < leavesEndX_)
      throw std::logic_error("LevelSetBuilder: a tile at x " + std::to_string(t.origin[0]) + " after leaves up to x " +
                             std::to_string(leavesEndX_) + " it may cover");
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
  std::unique_ptr<detail::LevelSetTree> tree = std::move(tree_);
  tree->write(path, meta);
}

}  // namespace frep::io
