// A 10^4-point reconstruction (frVolumeSplineFile, Pasko-Survey) compiles and meshes on the
// farm: two worker processes get the point file with the job, and the mesh lies on the
// scanned ellipsoid.
#include <cmath>
#include <sstream>
#include <sys/stat.h>

#include "farm_runner.h"
#include "mesh_files.h"

using namespace frep_cli_test;

namespace {

class VolumeSplineCli : public FarmTest {};

// Distance from q to the ellipsoid x^2 + (y/0.8)^2 + (z/0.6)^2 = 1, to first order.
double ellipsoidDistance(const mesh_checks::Vec3& q) {
  const double F = q[0] * q[0] + q[1] * q[1] / 0.64 + q[2] * q[2] / 0.36 - 1.0;
  const double g[3] = {2 * q[0], 2 * q[1] / 0.64, 2 * q[2] / 0.36};
  return std::fabs(F) / std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
}

}  // namespace

TEST_F(VolumeSplineCli, TenThousandPointScanMeshesOnTwoWorkers) {
  ASSERT_EQ(::mkdir(path("scan").c_str(), 0755), 0);
  std::ostringstream pts;
  pts.precision(17);
  const int n = 10000;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z), t = golden * i;
    const double x = r * std::cos(t), y = r * std::sin(t);
    pts << x << " " << 0.8 * y << " " << 0.6 * z << " " << x << " " << y / 0.8 << " " << z / 0.6 << "\n";
  }
  write("scan/ellipsoid.xyz", pts.str());
  // The file is named relative to the model, which is not in the working directory.
  write("scan/scan.hf", "scan(x[3], a[1]) { scan = frVolumeSplineFile(x, \"ellipsoid.xyz\", 0.02); }\n");
  RunResult r = run("mesh scan/scan.hf -b 1.2 --res 48 --workers 2 --brick 32 --no-progress --heartbeat-ms 100 -O e.ply");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string report = readText(path("e.ply.report.json"));
  EXPECT_NE(report.find("\"poisoned\": []"), std::string::npos) << report;
  ReadMesh m = readPly(readText(path("e.ply")));
  ASSERT_GT(m.triangles.size(), 500u);  // simplified (the default tolerance)
  EXPECT_EQ(mesh_checks::checkEdgePairs(m.triangles, m.positions.size()), "");
  const double voxel = 2.4 / 48;
  double worst = 0.0;
  for (const auto& q : m.positions) worst = std::max(worst, ellipsoidDistance(q));
  EXPECT_LE(worst, 0.5 * voxel) << "vertices off the scanned ellipsoid";
}
