// `frep mesh` on the farm, end to end through the built binaries: the same bytes for any worker
// count and brick size (PLY, OBJ, STL), the report beside the output, small jobs in-process by
// default, SIGTERM and --resume, poisoned bricks, JSON progress, and the farm options' errors.
#include <chrono>
#include <thread>

#include "farm_runner.h"

using namespace frep_cli_test;

namespace {

class MeshFarmCli : public FarmTest {
 protected:
  void SetUp() override {
    FarmTest::SetUp();
    write("part.hf", kPartModel);
  }
  static std::string meshArgs(const std::string& out, int res = 64) {
    return "mesh part.hf -b 1 --res " + std::to_string(res) + " --no-progress --heartbeat-ms 100 -O " + out;
  }
};

}  // namespace

TEST_F(MeshFarmCli, SameBytesForAnyWorkerCountAndBrickSize) {
  RunResult r0 = run(meshArgs("w0.ply") + " --workers 0 --brick 64");
  ASSERT_EQ(r0.code, 0) << r0.err;
  const std::string reference = readText(path("w0.ply"));
  ASSERT_GT(reference.size(), 10000u);
  EXPECT_NE(r0.out.find("bricks 1 (1 computed, 0 from the journal)"), std::string::npos) << r0.out;
  for (const char* variant : {"--workers 0 --brick 32", "--workers 2 --brick 32", "--workers 2 --brick 64",
                              "--workers 4 --brick 32", "--workers 4 --brick 64"}) {
    SCOPED_TRACE(variant);
    RunResult r = run(meshArgs("w.ply") + " " + variant);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(readText(path("w.ply")) == reference) << "output bytes differ";
    std::string report = readText(path("w.ply.report.json"));
    EXPECT_NE(report.find("\"operation\": \"mesh\""), std::string::npos) << report;
    EXPECT_NE(report.find("\"poisoned\": []"), std::string::npos) << report;
    EXPECT_GT(jsonNumber(report, "triangles"), 200);
    EXPECT_NE(r.out.find("report w.ply.report.json"), std::string::npos) << r.out;
  }
  EXPECT_FALSE(fileExists(path("w.ply.journal")));  // removed once the output is complete
  // OBJ and STL: the same bytes in-process and on two workers with another brick size.
  for (const char* ext : {"obj", "stl"}) {
    SCOPED_TRACE(ext);
    ASSERT_EQ(run(meshArgs(std::string("a.") + ext) + " --workers 0 --brick 64").code, 0);
    ASSERT_EQ(run(meshArgs(std::string("b.") + ext) + " --workers 2 --brick 32 --tolerance 0").code, 0);
    ASSERT_EQ(run(meshArgs(std::string("c.") + ext) + " --workers 0 --brick 16 --tolerance 0").code, 0);
    ASSERT_EQ(run(meshArgs(std::string("d.") + ext) + " --workers 2 --brick 32").code, 0);
    EXPECT_TRUE(readText(path(std::string("a.") + ext)) == readText(path(std::string("d.") + ext)));
    EXPECT_TRUE(readText(path(std::string("b.") + ext)) == readText(path(std::string("c.") + ext)));
    EXPECT_FALSE(readText(path(std::string("a.") + ext)) == readText(path(std::string("b.") + ext)));  // simplified
    EXPECT_TRUE(fileExists(path(std::string("b.") + ext + ".report.json")));
  }
}

// Without --workers, a grid of at most 64^3 points is computed in-process (the farm's start
// would cost more, docs/cli.md) and the report and summary say so; one point more, or an explicit
// --workers, and workers compute it. The bytes are the farm's either way.
TEST_F(MeshFarmCli, SmallJobWithoutWorkerCountRunsInProcess) {
  RunResult small = run(meshArgs("s.ply", 64));
  ASSERT_EQ(small.code, 0) << small.err;
  std::string report = readText(path("s.ply.report.json"));
  EXPECT_NE(report.find("\"in_process_rule\": \"small job (64x64x64 grid points"), std::string::npos) << report;
  EXPECT_EQ(jsonNumber(report, "workers_seen"), 0) << report;
  EXPECT_NE(small.out.find("workers 0 (in-process: small job)"), std::string::npos) << small.out;
  EXPECT_NE(small.err.find("small job (64x64x64 grid points, at most 64^3): computed in-process"), std::string::npos)
      << small.err;
  RunResult farm = run(meshArgs("f.ply", 64) + " --workers 2");
  ASSERT_EQ(farm.code, 0) << farm.err;
  report = readText(path("f.ply.report.json"));
  EXPECT_NE(report.find("\"in_process_rule\": null"), std::string::npos) << report;
  EXPECT_EQ(jsonNumber(report, "workers_seen"), 2) << report;
  EXPECT_TRUE(readText(path("s.ply")) == readText(path("f.ply"))) << "output bytes differ";
  RunResult big = run(meshArgs("b.ply", 65));  // 65^3 points: one more than a default brick
  ASSERT_EQ(big.code, 0) << big.err;
  report = readText(path("b.ply.report.json"));
  EXPECT_NE(report.find("\"in_process_rule\": null"), std::string::npos) << report;
  EXPECT_GE(jsonNumber(report, "workers_seen"), 1) << report;
  EXPECT_EQ(big.out.find("in-process"), std::string::npos) << big.out;
  // frep sample follows the same rule; --verify needs workers, so it keeps them.
  RunResult sample = run("sample part.hf -b 1 --res 32 --no-progress -O s.vdb");
  ASSERT_EQ(sample.code, 0) << sample.err;
  EXPECT_NE(readText(path("s.vdb.report.json")).find("\"in_process_rule\": \"small job"), std::string::npos);
  RunResult verified = run("sample part.hf -b 1 --res 32 --no-progress --verify 1 -O v.vdb");
  ASSERT_EQ(verified.code, 0) << verified.err;
  report = readText(path("v.vdb.report.json"));
  EXPECT_NE(report.find("\"in_process_rule\": null"), std::string::npos) << report;
  EXPECT_GE(jsonNumber(report, "workers_seen"), 1) << report;
}

TEST_F(MeshFarmCli, SigtermStopsTheMasterWhichResumesLater) {
  ASSERT_EQ(run(meshArgs("ref.ply", 96) + " --workers 0 --brick 32").code, 0);
  pid_t master = start(meshArgs("out.ply", 96) + " --workers 2 --brick 32", "FREP_TEST_SLOW_MS=150");
  for (int i = 0; i < 200 && journalRecords("out.ply.journal") < 3; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  kill(master, SIGTERM);
  EXPECT_EQ(waitFor(master), 6);
  EXPECT_NE(readText(path(".bg.err")).find("--resume"), std::string::npos);
  EXPECT_FALSE(fileExists(path("out.ply")));
  EXPECT_TRUE(fileExists(path("out.ply.report.json")));
  size_t journaled = journalRecords("out.ply.journal");
  ASSERT_GE(journaled, 3u);
  ASSERT_LT(journaled, 27u);
  RunResult resumed = run(meshArgs("out.ply", 96) + " --workers 2 --brick 32 --resume");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  std::string report = readText(path("out.ply.report.json"));
  EXPECT_EQ(jsonNumber(report, "from_journal"), long(journaled)) << report;
  EXPECT_EQ(jsonNumber(report, "computed"), 27 - long(journaled)) << report;
  EXPECT_TRUE(readText(path("out.ply")) == readText(path("ref.ply")));
}

TEST_F(MeshFarmCli, PoisonedBrickExitsFiveAndIsNamed) {
  std::string full = "cd '" + dir_ + "' && FREP_TEST_CRASH_BRICK=2 '" FREP_BINARY "' " + meshArgs("out.ply") +
                     " --workers 2 --brick 32 >" + path(".out") + " 2>" + path(".err");
  int status = std::system(full.c_str());
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 5);
  std::string err = readText(path(".err"));
  EXPECT_NE(err.find("brick 2 voxels [0,32,0)-(32,64,32)"), std::string::npos) << err;
  EXPECT_FALSE(fileExists(path("out.ply")));
  EXPECT_TRUE(fileExists(path("out.ply.journal")));
  EXPECT_TRUE(fileExists(path("out.ply.report.json")));
}

// A journal binds the brick edge: resumed without the first run's --workers/--brick (here the
// small-job default, in-process on bricks of 64) it is refused as another job's, instead of its
// bricks of 32 being merged as bricks of 64 (an open mesh); with them the job completes.
TEST_F(MeshFarmCli, ResumeWithAnotherBrickEdgeIsRefused) {
  ASSERT_EQ(run(meshArgs("ref.ply") + " --workers 0").code, 0);
  std::string full = "cd '" + dir_ + "' && FREP_TEST_CRASH_BRICK=5 '" FREP_BINARY "' " + meshArgs("out.ply") +
                     " --workers 2 --brick 32 >/dev/null 2>&1";
  int status = std::system(full.c_str());
  ASSERT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 5);
  ASSERT_TRUE(fileExists(path("out.ply.journal")));
  RunResult other = run(meshArgs("out.ply") + " --resume");
  EXPECT_EQ(other.code, 7) << other.err;
  EXPECT_NE(other.err.find("belongs to another job"), std::string::npos) << other.err;
  EXPECT_FALSE(fileExists(path("out.ply")));
  RunResult same = run(meshArgs("out.ply") + " --resume --workers 2 --brick 32");
  ASSERT_EQ(same.code, 0) << same.err;
  EXPECT_TRUE(readText(path("out.ply")) == readText(path("ref.ply"))) << "output bytes differ";
}

TEST_F(MeshFarmCli, JsonProgressEventsForBatchSystems) {
  RunResult r = run(meshArgs("j.ply") + " --workers 2 --brick 32 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("{\"event\":\"listening\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("{\"event\":\"progress\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("{\"event\":\"done\",\"output\":\"j.ply\""), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("wrote j.ply"), std::string::npos) << r.err;  // the summary goes to stderr
}

TEST_F(MeshFarmCli, BadFarmArgumentsAreNamed) {
  struct Case {
    const char* args;
    const char* message;
  } cases[] = {
      {" --brick 12", "--brick: expected a multiple of 8 voxels from 8 to 1024"},
      {" --brick 0", "--brick: expected a multiple of 8 voxels from 8 to 1024"},
      {" --workers -2", "--workers: expected an integer from -1 to 4096"},
      {" --listen localhost:5", "--listen: expected tcp://"},
      {" --threads -1", "--threads: expected 0"},
      {" --expect-workers -1", "--expect-workers: expected an integer from 0 to 4096"},
  };
  for (const Case& c : cases) {
    RunResult r = run(meshArgs("x.ply") + c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
  }
  RunResult r = run("mesh part.hf -b 1 --res 64 -O x.ply --heartbeat-ms 5");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--heartbeat-ms: expected an integer from 10 to 600000"), std::string::npos) << r.err;
  EXPECT_EQ(listing(), "part.hf");  // nothing written, not even a report
  EXPECT_EQ(run(meshArgs("x.ply") + " --workers 2 --curve missing").code, 7);  // farm error: no keys
  EXPECT_FALSE(fileExists(path("x.ply")));
}
