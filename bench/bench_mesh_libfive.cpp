// libfive's Mesh::render (dual contouring, its default) on bench_mesh.cpp's model, for a measured
// per-core comparison instead of libfive's published figure. Not part of the build: compiled by
// bench_mesh_libfive.py against a libfive build kept outside this repository.
//   usage: bench_mesh_libfive N out.ply [workers]
// Prints: N workers wall_s cpu_s triangles vertices level voxel-eq/cpu-s (N^3 / CPU seconds).
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "libfive/render/brep/mesh.hpp"
#include "libfive/render/brep/region.hpp"
#include "libfive/render/brep/settings.hpp"
#include "libfive/tree/tree.hpp"

static double cpuSeconds() {
  struct rusage ru {};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s N out.ply [workers]\n", argv[0]);
    return 2;
  }
  const int n = std::atoi(argv[1]);
  const unsigned workers = argc > 3 ? unsigned(std::atoi(argv[3])) : 1;
  using libfive::Tree;
  const Tree x = Tree::X(), y = Tree::Y(), z = Tree::Z();
  const Tree g = sin(8 * x) * cos(8 * y) + sin(8 * y) * cos(8 * z) + sin(8 * z) * cos(8 * x);
  // libfive's solid is f < 0: the negation of frepfarm's min(1 - |x|^2, 0.3 - |g|).
  const Tree t = max(square(x) + square(y) + square(z) - 1, abs(g) - 0.3);

  const libfive::Region<3> region({-1.1, -1.1, -1.1}, {1.1, 1.1, 1.1});
  libfive::BRepSettings settings;
  settings.workers = workers;
  // Depth is ceil(log2(2.2 / min_feature)) in float arithmetic: 2.2 / N exactly can round up
  // to one level deeper (2N cells), so nudge it by 1e-6 to get N cells per axis.
  settings.min_feature = 2.2 / n * (1 + 1e-6);
  const int level = region.withResolution(settings.min_feature).level;

  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpuSeconds();
  auto mesh = libfive::Mesh::render(t, region, settings);
  const double cpu = cpuSeconds() - c0;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!mesh) {
    std::fprintf(stderr, "render failed\n");
    return 1;
  }

  // Binary PLY; vertex 0 is libfive's reserved marker, kept so indices stay as libfive wrote them.
  FILE* f = std::fopen(argv[2], "wb");
  if (!f) {
    std::perror(argv[2]);
    return 3;
  }
  std::fprintf(f,
               "ply\nformat binary_little_endian 1.0\nelement vertex %zu\nproperty float x\nproperty float y\n"
               "property float z\nelement face %zu\nproperty list uchar int vertex_indices\nend_header\n",
               mesh->verts.size(), mesh->branes.size());
  for (const auto& v : mesh->verts) std::fwrite(v.data(), sizeof(float), 3, f);
  for (const auto& tri : mesh->branes) {
    const unsigned char three = 3;
    const int idx[3] = {int(tri[0]), int(tri[1]), int(tri[2])};
    std::fwrite(&three, 1, 1, f);
    std::fwrite(idx, sizeof(int), 3, f);
  }
  std::fclose(f);

  std::printf("%d %u %.3f %.3f %zu %zu %d %.4g\n", n, workers, wall, cpu, mesh->branes.size(), mesh->verts.size() - 1,
              level, double(n) * n * n / cpu);
  return 0;
}
