// Small hostile input files (issue 31): headers that state more than the file holds, counts of
// 2^31 and 2^64, non-finite numbers, truncated ASCII STL, special files. Every reader refuses
// them at once, with the file and the line or byte, before allocating what they state.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "frep/io/error.h"
#include "frep/io/input_file.h"
#include "frep/io/mesh_reader.h"
#include "frep/lang/hyperfun.h"

using namespace frep;

namespace {

using Clock = std::chrono::steady_clock;

// The reader's error for `bytes` as a file named `name`, and how long it took to refuse it.
std::string refusal(const std::string& name, const std::string& bytes, double* seconds = nullptr) {
  const auto t0 = Clock::now();
  std::string what;
  try {
    io::parseMesh(name, bytes);
    what = "(accepted)";
  } catch (const io::Error& e) {
    EXPECT_EQ(e.code, io::kExitIoError) << e.what();
    what = e.what();
  }
  if (seconds) *seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return what;
}

// At most `bytes` of address space grown while `f` runs (VmPeak is monotone: the test fails if
// an allocation anywhere near what a header states was made).
long vmPeakKb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmPeak:", 0) == 0) return std::stol(line.substr(7));
  return 0;
}

const std::string kCubePlyHeader = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                   "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

}  // namespace

// The 150-byte PLY of issue 31: `element vertex 2000000000` with no properties wanted 48 GB;
// an element of 2^31 entries spun 2.2 s per header line. Now: refused at once, nothing allocated.
TEST(HostileFiles, PlyCountsBeyondTheFileAreRefusedBeforeAllocating) {
  const long before = vmPeakKb();
  std::string noProps = "ply\nformat binary_little_endian 1.0\ncomment 150 bytes\nelement vertex 2000000000\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  ASSERT_LE(noProps.size(), 150u);
  noProps.resize(150, '\0');
  double seconds = 0;
  std::string why = refusal("v.ply", noProps, &seconds);
  EXPECT_NE(why.find("v.ply: the vertex element has no scalar property 'x'"), std::string::npos) << why;
  EXPECT_LT(seconds, 0.05);
  std::printf("[ hostile  ] 150-byte PLY, 2e9 vertices without properties: refused in %.1f us\n", seconds * 1e6);
  const std::string big = "ply\nformat binary_little_endian 1.0\nelement vertex 2147483648\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n" + std::string(64, '\0');
  why = refusal("big.ply", big, &seconds);
  EXPECT_NE(why.find("big.ply: element 'vertex' states 2147483648 entries of at least 12 bytes each, more than the 64 "
                     "bytes after the header"),
            std::string::npos)
      << why;
  EXPECT_LT(seconds, 0.05);
  std::printf("[ hostile  ] PLY of 2^31 vertices in 64 bytes: refused in %.1f us\n", seconds * 1e6);
  why = refusal("other.ply", "ply\nformat ascii 1.0\nelement junk 2147483648\nproperty uchar a\nend_header\n1 2 3\n");
  EXPECT_NE(why.find("other.ply: element 1 states 2147483648 entries"), std::string::npos) << why;
  why = refusal("wrap.ply", "ply\nformat ascii 1.0\nelement vertex 18446744073709551615\nproperty float x\n"
                            "property float y\nproperty float z\nend_header\n0 0 0\n");
  EXPECT_NE(why.find("states 18446744073709551615 entries"), std::string::npos) << why;
  why = refusal("neg.ply", "ply\nformat ascii 1.0\nelement vertex -1\nproperty float x\nend_header\n");
  EXPECT_NE(why.find("neg.ply: header line 3: the element count is not a whole number"), std::string::npos) << why;
  // A list whose length is more than the file has left.
  why = refusal("list.ply", kCubePlyHeader + "0 0 0\n1 0 0\n0 1 0\n255 0 1 2\n");
  EXPECT_NE(why.find("list.ply: face 0: bad list length at byte"), std::string::npos) << why;
  std::string binList = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
  binList += std::string(36, '\0');
  const uint32_t huge = 0xfffffff0u;
  binList.append(reinterpret_cast<const char*>(&huge), 4);
  why = refusal("binlist.ply", binList);
  EXPECT_NE(why.find("binlist.ply: face 0: bad list length at byte"), std::string::npos) << why;
  EXPECT_LT(vmPeakKb() - before, 64 * 1024) << "a reader allocated what a header stated";
}

// Non-finite or non-numeric values are refused with the byte or line, never quoted.
TEST(HostileFiles, NonFiniteValuesAreRefusedNamingWhereNotWhat) {
  std::string why = refusal("n.ply", kCubePlyHeader + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n");
  EXPECT_NE(why.find("n.ply: not a finite number at byte"), std::string::npos) << why;
  why = refusal("i.ply", kCubePlyHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n");
  EXPECT_NE(why.find("i.ply: not a whole number at byte"), std::string::npos) << why;
  why = refusal("s.ply", kCubePlyHeader + "0 0 0\n1 0 0\n0 1 SECRET\n3 0 1 2\n");
  EXPECT_EQ(why.find("SECRET"), std::string::npos) << why;
  why = refusal("n.obj", "v 0 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NE(why.find("n.obj: line 2: not a finite number at byte 13"), std::string::npos) << why;
  why = refusal("e.obj", "v 0 0 0\nv 1 1e999 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NE(why.find("e.obj: line 2: not a finite number"), std::string::npos) << why;
  why = refusal("f.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 SECRET\n");
  EXPECT_NE(why.find("f.obj: line 4: bad face vertex at byte"), std::string::npos) << why;
  EXPECT_EQ(why.find("SECRET"), std::string::npos) << why;
  std::string stl(84 + 50, '\0');
  stl[80] = 1;
  const float inf = INFINITY;
  std::memcpy(&stl[84 + 12 + 4], &inf, 4);
  why = refusal("n.stl", stl);
  EXPECT_NE(why.find("n.stl: facet 0: non-finite coordinate"), std::string::npos) << why;
  why = refusal("n2.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 nan\nvertex 0 1 0\n"
                          "endloop\nendfacet\nendsolid s\n");
  EXPECT_NE(why.find("n2.stl:5: not a finite number in a vertex"), std::string::npos) << why;
}

// Truncated ASCII STL was accepted (its open edges only warned about): now refused with
// file:line, whether it stops inside a facet or after one, before endsolid.
TEST(HostileFiles, TruncatedAsciiStlIsRefusedWithFileAndLine) {
  const std::string facet = "facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n"
                            " endloop\nendfacet\n";
  const std::string whole = "solid t\n" + facet + facet + "endsolid t\n";
  EXPECT_EQ(io::parseMesh("w.stl", whole).triangles.size(), 2u);
  std::string why = refusal("t.stl", "solid t\n" + facet + facet);
  EXPECT_NE(why.find("t.stl:15: truncated ASCII STL (no endsolid)"), std::string::npos) << why;
  why = refusal("t.stl", "solid t\n" + facet + facet.substr(0, 43));
  EXPECT_NE(why.find("t.stl:11: truncated ASCII STL (the file ends inside a vertex)"), std::string::npos) << why;
  why = refusal("t.stl", "solid t\n" + facet + "facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n endloop\nendfacet\nendsolid\n");
  EXPECT_NE(why.find("t.stl:12: a facet with fewer than 3 vertices"), std::string::npos) << why;
  why = refusal("t.stl", "solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n"
                         "  vertex 1 1 0\n endloop\nendfacet\nendsolid\n");
  EXPECT_NE(why.find("t.stl:7: a facet with more than 3 vertices"), std::string::npos) << why;
  // A binary STL whose 80-byte header starts with "solid" is binary all the same (its size
  // is what its facet count says).
  std::string bin(84 + 50, '\0');
  std::memcpy(&bin[0], "solid but binary", 16);
  bin[80] = 1;
  const float corner[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::memcpy(&bin[84 + 12], corner, sizeof corner);
  EXPECT_EQ(io::parseMesh("b.stl", bin).triangles.size(), 1u);
}

// Special files are refused at once by every whole-file reader: not read to the end of memory
// (/dev/zero), not waited on (a FIFO with no writer), not followed as directories.
TEST(HostileFiles, SpecialFilesAreRefusedAtOnce) {
  char tmpl[] = "/tmp/frep_hostile_XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  const std::string fifo = dir + "/f.stl";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const auto t0 = Clock::now();
  for (const std::string& path : {std::string("/dev/zero"), fifo, dir + "/", std::string("/dev/null")}) {
    try {
      io::readInputFile(path);
      ADD_FAILURE() << path << " was read";
    } catch (const io::Error& e) {
      EXPECT_EQ(e.code, io::kExitIoError);
      EXPECT_NE(std::string(e.what()).find("'" + path + "'"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(io::readMesh(fifo), io::Error);
  EXPECT_THROW(io::readMesh("/dev/zero.stl"), io::Error);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 1.0);
  // The size is checked before anything is read or allocated.
  std::ofstream(dir + "/big.stl") << std::string(100, 'x');
  try {
    io::readInputFile(dir + "/big.stl", 64);
    ADD_FAILURE() << "a file over the limit was read";
  } catch (const io::Error& e) {
    EXPECT_NE(std::string(e.what()).find("is 100 bytes, more than the limit of 64 bytes"), std::string::npos) << e.what();
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}

// The point files of frVolumeSplineFile (lang's PLY reader) are bounded the same way.
TEST(HostileFiles, PointCloudPlyCountsBeyondTheFileAreRefused) {
  lang::CompileOptions opt;
  opt.files["p.ply"] = "ply\nformat binary_little_endian 1.0\nelement vertex 2000000000\nproperty float x\n"
                       "property float y\nproperty float z\nproperty float value\nend_header\n" + std::string(32, '\0');
  const auto t0 = Clock::now();
  lang::CompileResult r = lang::compile("m(x[3], a[1]) { m = frVolumeSplineFile(x, \"p.ply\", 0); }", "m.hf", opt);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 0.05);
  ASSERT_FALSE(r.ok);
  EXPECT_NE(r.diagnostics[0].message.find("p.ply: the header states 2000000000 vertices of at least 16 bytes each, "
                                          "more than the 32 bytes after it"),
            std::string::npos)
      << r.diagnostics[0].message;
}
