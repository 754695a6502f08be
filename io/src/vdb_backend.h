// frepfarm's OpenVDB code behind one table of entry points. OpenVDB costs ~40 ms of dynamic
// linking at every process start (61,000 symbol relocations), more than a small `frep mesh` run
// takes; frep and frep-worker therefore load it only when a job reads or writes a .vdb file
// (vdb_backend_loaded.cpp opens the module libfrep_vdb.so), while the library frep_io, the Python
// module and the tests link it in (vdb_backend_linked.cpp). The public functions of vdb_reader.h,
// vdb_writer.h and geometry_files.h forward to this table (vdb_entry.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "frep/io/vdb_reader.h"
#include "frep/io/vdb_writer.h"

namespace frep {
class DistanceField;
}

namespace frep::io::detail {

// The OpenVDB tree a LevelSetBuilder fills (vdb_writer.cpp); the order checks stay in the builder.
class LevelSetTree {
 public:
  virtual ~LevelSetTree() = default;
  virtual void addTiles(const std::vector<Tile>& tiles) = 0;
  virtual void addLeaves(const std::vector<LeafBlock>& leaves) = 0;
  virtual uint64_t leavesWrittenOut() const = 0;
  virtual void write(const std::string& path, const VdbMetadata& meta) = 0;
};

struct VdbBackend {
  SampledVdb (*readSampledVdb)(const std::string& path, const std::string& gridName);
  void (*writeLevelSet)(const std::string& path, const SampleResult& result, const VdbMetadata& meta);
  std::unique_ptr<LevelSetTree> (*newLevelSetTree)(const GridSpec& grid, int bandVoxels, bool spillLeaves);
  std::shared_ptr<const DistanceField> (*readVolumeField)(const std::string& path, const std::string& bytes,
                                                          const std::string& grid, uint64_t fileHash);
};

// The table of the OpenVDB code in this binary (vdb_backend_linked.cpp, with that code).
const VdbBackend& openVdbBackend();
// The table this program uses: openVdbBackend() where the OpenVDB code is linked in, the loaded
// module's in frep and frep-worker (vdb_backend_loaded.cpp, whose definition the linker takes
// first). Throws Error(kExitInternal) naming the paths tried when the module cannot be loaded.
const VdbBackend& vdbBackend();
// vdb_backend_loaded.cpp: references the frepfarm functions the module needs from the program.
void keepForModule(std::vector<LeafBlock>& leaves, std::vector<Tile>& tiles);

// The implementations (vdb_reader.cpp, vdb_writer.cpp, volume_field.cpp).
SampledVdb openVdbReadSampled(const std::string& path, const std::string& gridName);
void openVdbWriteLevelSet(const std::string& path, const SampleResult& result, const VdbMetadata& meta);
std::unique_ptr<LevelSetTree> openVdbLevelSetTree(const GridSpec& grid, int bandVoxels, bool spillLeaves);
std::shared_ptr<const DistanceField> openVdbReadVolumeField(const std::string& path, const std::string& bytes,
                                                            const std::string& grid, uint64_t fileHash);

// The module's entry point (a frep::io::ModuleEntry: a module of another build answers nothing).
inline constexpr const char* kVdbModuleEntry = "frep_vdb_backend";

}  // namespace frep::io::detail
