// Fuzz loops that run the frep binary as a process once per input: each guarantee below holds
// for hundreds of inputs made by the test, which takes about a minute, so these are not in ctest
// but in the bounded fuzz run (tests/fuzz/run_fuzz.sh, run by deploy/test.sh), which builds and
// runs this program (cli_process_fuzz) from the Release build. docs/cli.md lists the guarantee.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "hardening_fixture.h"

using namespace frep_cli_test;

namespace {
class ProcessFuzz : public Hardening {};
}  // namespace

// frep mesh of a damaged .vdb (prefixes: every 5th length in the header, every 401st after, the
// last 64 bytes; one bit flipped at every 3rd offset in the header, every 499th after): under a
// 2 GiB address-space limit it never crashes, never exits 0 with a mesh other than the intact
// file's, and exits 3 (or 1: no float grid) the same way on a second run.
TEST_F(ProcessFuzz, DamagedVdbIsRefusedNotMeshed) {
  write("sphere.hf", kSphere);
  ASSERT_EQ(run(sampleArgs("good.vdb")).code, 0);
  const std::string good = readText(path("good.vdb"));
  std::ofstream(path("bad.vdb"), std::ios::binary) << good;  // the mesh's header names its input
  ASSERT_EQ(run("mesh bad.vdb -O good.ply").code, 0);
  const std::string goodMesh = readText(path("good.ply"));
  std::vector<std::pair<std::string, std::string>> corpus;  // what, bytes
  for (size_t n = 0; n < good.size(); n += n < 200 ? 5 : 401)
    corpus.push_back({"prefix " + std::to_string(n), good.substr(0, n)});
  for (size_t n = good.size() - 64; n < good.size(); n += 7)
    corpus.push_back({"prefix " + std::to_string(n), good.substr(0, n)});
  for (size_t at = 0; at < good.size(); at += at < 200 ? 3 : 499) {
    std::string b = good;
    b[at] = char(b[at] ^ (1 << (at % 8)));
    corpus.push_back({"bit flip at " + std::to_string(at), b});
  }
  int refused = 0, identical = 0;
  for (size_t i = 0; i < corpus.size(); ++i) {
    const auto& [what, bytes] = corpus[i];
    std::ofstream(path("bad.vdb"), std::ios::binary) << bytes;
    RunResult r = runWith("ulimit -v 2097152", "mesh bad.vdb -O bad.ply");
    ASSERT_TRUE(r.code == 0 || r.code == 1 || r.code == 3) << what << ": exit " << r.code << "\n" << r.err;
    if (r.code == 0) {
      ASSERT_EQ(readText(path("bad.ply")), goodMesh) << what << ": exit 0 with another mesh";
      ++identical;
    } else {
      ++refused;
      EXPECT_NE(r.err.find("bad.vdb"), std::string::npos) << what << ": " << r.err;
      EXPECT_FALSE(fileExists(path("bad.ply"))) << what;
    }
    if (i % 5 == 0) EXPECT_EQ(runWith("ulimit -v 2097152", "mesh bad.vdb -O bad2.ply").code, r.code) << what;
    std::remove(path("bad.ply").c_str());
    std::remove(path("bad2.ply").c_str());
  }
  EXPECT_GT(refused, int(corpus.size()) / 2);
  std::cout << corpus.size() << " damaged files: " << refused << " refused, " << identical << " meshed identically\n";
  EXPECT_TRUE(noTemporaries()) << listing();
}
