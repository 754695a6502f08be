// Mistyped verbs and options: exit 2 with the closest verb or option ("did you mean"), and with
// --json a JSON error event on stdout as for any other error (cli/suggest.h, docs/cli.md).
#include "frep_runner.h"

using namespace frep_cli_test;

namespace {
bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }
}  // namespace

TEST_F(FrepTest, MistypedVerbsAndOptionsAreNamedWithTheirClosestName) {
  write("s.hf", kSphere);
  struct Case {
    std::string args, message;
  } cases[] = {
      {"mseh s.hf -O m.ply", "unknown verb 'mseh' (did you mean 'mesh'?); the verbs are check, eval"},
      {"smaple s.hf -O s.vdb", "unknown verb 'smaple' (did you mean 'sample'?)"},
      {"mesh s.hf --ress 32 -O m.ply", "--ress: not an option of frep mesh (did you mean --res?)"},
      {"sample s.hf --workrs 2 -O s.vdb", "--workrs: not an option of frep sample (did you mean --workers?)"},
      {"render s.hf --azimut 30 -O r.png", "--azimut: not an option of frep render (did you mean --azimuth?)"},
  };
  for (const Case& c : cases) {
    RunResult r = run(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, c.message)) << c.args << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << c.args << "\n" << r.out;  // no --json: no event
  }
  // Nothing close: no suggestion.
  RunResult far = run("frob s.hf");
  EXPECT_TRUE(contains(far.err, "unknown verb 'frob'; the verbs are")) << far.err;
  EXPECT_FALSE(contains(far.err, "did you mean")) << far.err;
  EXPECT_EQ(listing(), "s.hf");  // no output was started
}

TEST_F(FrepTest, ABadArgumentWithJsonIsAJsonErrorEvent) {
  write("s.hf", kSphere);
  for (const std::string args :
       {"mesh s.hf --ress 32 -O m.ply --json", "sample s.hf --json --band 0 -O s.vdb", "mseh s.hf --json"}) {
    RunResult r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
    // One line: {"event":"error","exit_code":2,"message":...} naming what is wrong.
    EXPECT_EQ(r.out.rfind("{\"event\":\"error\",\"exit_code\":2,\"message\":\"", 0), 0u) << args << "\n" << r.out;
    EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << r.out;
  }
  EXPECT_TRUE(contains(run("mesh s.hf --ress 32 -O m.ply --json").out, "did you mean --res?"));
}
