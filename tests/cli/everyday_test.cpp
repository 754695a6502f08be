// The everyday details of issue 16: SPDLOG_LEVEL, --json phase and error events, frep-worker
// --version, the progress bar with log lines on a terminal, mesh simplification progress.
#include <gtest/gtest.h>

#include <string>

#include "frep_runner.h"

using namespace frep_cli_test;

namespace {

size_t count(const std::string& s, const std::string& what) {
  size_t n = 0;
  for (size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_F(FrepTest, SpdlogLevelIsHonouredUnlessLogLevelIsGiven) {
  write("s.hf", kSphere);
  const std::string args = "sample s.hf --res 16 --workers 0 --no-progress";
  RunResult plain = run(args + " -O a.vdb");
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_NE(plain.err.find("frep: info: sampling"), std::string::npos) << plain.err;
  RunResult warn = capture("SPDLOG_LEVEL=warn '" FREP_BINARY "' " + args + " -O b.vdb");
  ASSERT_EQ(warn.code, 0) << warn.err;
  EXPECT_EQ(warn.err, "");
  RunResult named = capture("SPDLOG_LEVEL=info,frep=error '" FREP_BINARY "' " + args + " -O c.vdb");  // per logger
  ASSERT_EQ(named.code, 0) << named.err;
  EXPECT_EQ(named.err, "");
  RunResult option = capture("SPDLOG_LEVEL=warn '" FREP_BINARY "' --log-level info " + args + " -O d.vdb");
  ASSERT_EQ(option.code, 0) << option.err;
  EXPECT_NE(option.err.find("frep: info: sampling"), std::string::npos) << option.err;  // the option wins
  // Debug from the environment reaches the farm's own messages.
  RunResult workers = capture("SPDLOG_LEVEL=debug '" FREP_BINARY "' " + args.substr(0, args.find(" --workers")) +
                              " --workers 1 --no-progress -O e.vdb");
  ASSERT_EQ(workers.code, 0) << workers.err;
  EXPECT_NE(workers.err.find("frep: debug: "), std::string::npos) << workers.err;
}

TEST_F(FrepTest, FrepWorkerHasAVersion) {
  const std::string worker = std::string(FREP_BINARY).substr(0, std::string(FREP_BINARY).rfind('/')) + "/frep-worker";
  RunResult r = capture("'" + worker + "' --version");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("frep-worker ", 0), 0u) << r.out;
  RunResult frep = run("--version");
  EXPECT_NE(r.out.find(frep.out.substr(frep.out.rfind(' ') + 1)), std::string::npos) << r.out << " vs " << frep.out;
}

TEST_F(FrepTest, JsonHasPhaseAndErrorEvents) {
  write("s.hf", kSphere);
  RunResult s = run("sample s.hf --res 16 --workers 0 --json -O a.vdb");
  ASSERT_EQ(s.code, 0) << s.err;
  const size_t compute = s.out.find("{\"event\":\"phase\",\"phase\":\"compute\"}\n");
  const size_t writing = s.out.find("{\"event\":\"phase\",\"phase\":\"write\"}\n");
  const size_t done = s.out.find("{\"event\":\"done\",\"output\":\"a.vdb\",\"report\":\"a.vdb.report.json\"}\n");
  ASSERT_NE(compute, std::string::npos) << s.out;
  ASSERT_NE(writing, std::string::npos) << s.out;
  ASSERT_NE(done, std::string::npos) << s.out;
  EXPECT_LT(compute, writing);
  EXPECT_LT(writing, done);
  EXPECT_NE(s.out.find("\"eta_s\":"), std::string::npos) << s.out;

  RunResult m = run("mesh s.hf -b 1.5 --res 32 --workers 0 --json -O a.ply");
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_NE(m.out.find("{\"event\":\"phase\",\"phase\":\"simplify\"}\n"), std::string::npos) << m.out;
  // The simplification's passes report their progress, each ending at done == total.
  for (int pass = 1; pass <= 5; ++pass)
    EXPECT_NE(m.out.find("{\"event\":\"progress\",\"phase\":\"simplify\",\"pass\":" + std::to_string(pass)), std::string::npos)
        << m.out;
  EXPECT_LT(m.out.find("\"phase\":\"simplify\"}"), m.out.find("\"phase\":\"write\"}")) << m.out;
  // Reporting progress never changes the mesh.
  ASSERT_EQ(run("mesh s.hf -b 1.5 --res 32 --workers 0 --no-progress -O quiet.ply").code, 0);
  EXPECT_TRUE(readText(path("a.ply")) == readText(path("quiet.ply"))) << "the mesh differs with --json";

  // Errors: a model error (1) and a bad option (2), with the message, escaped.
  write("bad.hf", "my_model(x[3], a[1]) { my_model = \"1 - ; }\n");
  RunResult e = run("sample bad.hf --res 16 --workers 0 --json -O b.vdb");
  EXPECT_EQ(e.code, 1) << e.err;
  EXPECT_EQ(count(e.out, "{\"event\":\"error\",\"exit_code\":1,\"message\":\""), 1u) << e.out;
  EXPECT_EQ(e.out.find("\"event\":\"done\""), std::string::npos) << e.out;
  RunResult b = run("mesh s.hf --res 16 --brick 12 --json -O b.ply");
  EXPECT_EQ(b.code, 2);
  EXPECT_NE(b.out.find("{\"event\":\"error\",\"exit_code\":2,\"message\":\"--brick: "), std::string::npos) << b.out;
  // Without --json nothing goes to stdout on error.
  RunResult quiet = run("sample bad.hf --res 16 --workers 0 -O c.vdb");
  EXPECT_EQ(quiet.out, "");
}

// On a terminal (script(1) gives frep a pseudo-terminal): the bar is drawn, log lines that come
// while it is shown start on a line of their own, and no "ETA 0 s" is shown before the end.
TEST_F(FrepTest, ProgressBarOnATerminalKeepsLogLinesWhole) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "script(1) not installed";
  write("s.hf", kSphere);
  RunResult r = capture("script -qec \"'" FREP_BINARY "' mesh s.hf -b 1.5 --res 48 --workers 2 --brick 16 -O a.ply\" /dev/null");
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  const std::string& t = r.out;  // the terminal's bytes (stdout and stderr)
  ASSERT_NE(t.find("bricks"), std::string::npos) << t;
  ASSERT_NE(t.find("simplifying: pass 5 of 5"), std::string::npos) << t;
  size_t logs = 0;
  for (size_t at = t.find("frep: "); at != std::string::npos; at = t.find("frep: ", at + 1)) {
    ++logs;
    const bool lineStart = at == 0 || t[at - 1] == '\n' || t.compare(at < 4 ? 0 : at - 4, 4, "\r\033[K") == 0;
    EXPECT_TRUE(lineStart) << "a log line inside the bar at byte " << at << ": ..." << t.substr(at < 40 ? 0 : at - 40, 80);
  }
  EXPECT_GE(logs, 2u);  // "meshing ..." and "simplifying ..." at least, the latter while the bar is shown
  // The ETA of a bar that is not at its end is never a false 0 s.
  for (size_t at = t.find("ETA 0 s"); at != std::string::npos; at = t.find("ETA 0 s", at + 1)) {
    const size_t open = t.rfind('[', at);
    const std::string bar = t.substr(open, t.find(']', open) - open);
    EXPECT_EQ(bar.find('.'), std::string::npos) << "ETA 0 s on an unfinished bar: " << bar;
  }
}
