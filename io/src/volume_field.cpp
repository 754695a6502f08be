// A .vdb grid as a geometry field (geometry_files.h). One of the few translation units that
// include OpenVDB.
#include <openvdb/openvdb.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "frep/io/error.h"
#include "frep/io/geometry_files.h"
#include "frep/io/vdb_reader.h"
#include "checked_grid.h"
#include "vdb_backend.h"

namespace frep::io {
namespace {

class VolumeField : public DistanceField {
 public:
  VolumeField(openvdb::FloatGrid::ConstPtr grid, double sign, double offset, std::string name, uint64_t hash)
      : grid_(std::move(grid)), sign_(sign), offset_(offset), name_(std::move(name)), hash_(hash) {
    const openvdb::Vec3d vs = grid_->voxelSize();
    voxel_ = std::min({vs[0], vs[1], vs[2]});
    // |grad| of the trilinear interpolant in a cell is at most the per-axis largest difference
    // along that axis over the cell's edges; edges away from active voxels join equal tile or
    // background values (a level set's band separates inside from outside).
    const openvdb::FloatTree& tree = grid_->tree();
    double L[3] = {0, 0, 0};
    for (auto it = tree.cbeginValueOn(); it; ++it) {
      const openvdb::Coord c = it.getCoord();
      const double v = *it;
      if (!it.isVoxelValue()) continue;  // active tiles: constant inside, edges checked below
      for (int a = 0; a < 3; ++a)
        for (int s = -1; s <= 1; s += 2) {
          openvdb::Coord n = c;
          n[a] += s;
          L[a] = std::max(L[a], std::fabs(double(tree.getValue(n)) - v));
        }
    }
    lipschitz_ = std::sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]) / voxel_;
    if (!(lipschitz_ > 0)) lipschitz_ = 1e-300;  // constant field
  }
  double value(const double p[3]) const override {
    const openvdb::Vec3d q = grid_->transform().worldToIndex(openvdb::Vec3d(p[0], p[1], p[2]));
    const openvdb::FloatTree& tree = grid_->tree();
    const double fx = std::floor(q[0]), fy = std::floor(q[1]), fz = std::floor(q[2]);
    // Far outside the index range: the background (avoids int overflow).
    if (!(std::fabs(fx) < 1e9 && std::fabs(fy) < 1e9 && std::fabs(fz) < 1e9))
      return sign_ * double(tree.background()) + offset_;
    const int x = int(fx), y = int(fy), z = int(fz);
    const double u = q[0] - fx, v = q[1] - fy, w = q[2] - fz;
    double c[8];
    for (int k = 0; k < 8; ++k) c[k] = tree.getValue(openvdb::Coord(x + (k >> 2 & 1), y + (k >> 1 & 1), z + (k & 1)));
    const double c00 = c[0] + (c[4] - c[0]) * u, c01 = c[1] + (c[5] - c[1]) * u;
    const double c10 = c[2] + (c[6] - c[2]) * u, c11 = c[3] + (c[7] - c[3]) * u;
    const double c0 = c00 + (c10 - c00) * v, c1 = c01 + (c11 - c01) * v;
    return sign_ * (c0 + (c1 - c0) * w) + offset_;
  }
  double lipschitz() const override { return lipschitz_; }
  uint64_t contentHash() const override { return hash_; }
  std::string describe() const override { return name_; }

 protected:
  bool sameGeometry(const DistanceField& o) const override {
    const auto& v = static_cast<const VolumeField&>(o);
    return v.grid_ == grid_ || (v.name_ == name_ && v.sign_ == sign_ && v.offset_ == offset_);
  }

 private:
  openvdb::FloatGrid::ConstPtr grid_;
  double sign_, offset_, voxel_ = 1, lipschitz_ = 1;
  std::string name_;
  uint64_t hash_;
};

// OpenVDB reads grids from files (io::File needs to seek): the bytes go to a private temporary
// file, removed when the grid is read. Messages name the model's file, not the temporary one.
class TempFile {
 public:
  explicit TempFile(const std::string& bytes) {
    const char* dir = std::getenv("TMPDIR");
    std::string tmpl = std::string(dir && *dir ? dir : "/tmp") + "/frep-volume-XXXXXX";
    std::vector<char> buf(tmpl.begin(), tmpl.end());
    buf.push_back('\0');
    const int fd = ::mkstemp(buf.data());
    if (fd < 0) throw ioError("cannot create a temporary file in " + tmpl.substr(0, tmpl.rfind('/')) + ": " + std::strerror(errno));
    path_ = buf.data();
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
      if (n <= 0) {
        ::close(fd);
        throw ioError("cannot write the temporary file " + path_);
      }
      done += size_t(n);
    }
    ::close(fd);
  }
  ~TempFile() { ::unlink(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace

std::shared_ptr<const DistanceField> detail::openVdbReadVolumeField(const std::string& path, const std::string& bytes,
                                                                   const std::string& gridName, uint64_t fileHash) {
  openvdb::initialize();
  TempFile tmp(bytes);
  const openvdb::FloatGrid::Ptr grid =
      readCheckedFloatGrid(tmp.path(), {path, gridName, "frVolume's grid argument", "read", "frVolume"}).grid;
  if (!grid->transform().isLinear())
    throw Error(kExitModelError, path + ": grid '" + grid->getName() + "' has a non-linear transform (frVolume needs a linear one)");
  // frep sample writes value = -f (metadata frep_sign); OpenVDB level sets are negative inside:
  // both give f = -value. A fog volume (density, 0 outside) is inside where density >= 0.5.
  const bool fog = grid->getGridClass() == openvdb::GRID_FOG_VOLUME && !grid->getMetadata<openvdb::StringMetadata>("frep_sign");
  const double sign = fog ? 1.0 : -1.0, offset = fog ? -0.5 : 0.0;
  return std::make_shared<VolumeField>(grid, sign, offset, path + " grid '" + grid->getName() + "'", fileHash);
}

}  // namespace frep::io
