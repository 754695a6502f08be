// Conformance with hfp, HyperFun's original C interpreter, on the third-party corpus
// (../shared/corpus/hyperfun: 53 models and 471 values hfp computed, see its README). Every
// model must compile; every reference value must be reproduced to 1e-9 relative. The three
// files with literals such as 4.28626379701574e-16 are compared with
// expected_exponent_fixed.tsv, since frepfarm reads those literals correctly (docs/language.md,
// "Differences from hfp").
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "lang/lang_test_util.h"
#include "shared_corpus.h"

namespace frep::lang::testing {
namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = fs::path(FREP_SHARED_DIR) / "corpus" / "hyperfun";

struct Reference {
  std::string file, object;
  std::vector<double> params, x;
  double value = 0;
  int line = 0;
};

std::vector<double> numbers(const std::string& list) {
  std::vector<double> v;
  if (list == "-") return v;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) v.push_back(std::stod(item));
  return v;
}

std::vector<Reference> readTable(const fs::path& path) {
  std::vector<Reference> refs;
  std::ifstream in(path);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (n == 1 || line.empty()) continue;  // header
    std::stringstream ss(line);
    std::string f[5];
    for (auto& s : f) std::getline(ss, s, '\t');
    refs.push_back({f[0], f[1], numbers(f[2]), numbers(f[3]), std::stod(f[4]), n});
  }
  return refs;
}

// The files whose literals hfp misreads: their reference values come from the fixed table.
const std::set<std::string> kExponentQuirk = {"rgen_spheres_ring.hf", "rgen_spheres_minus_cube.hf",
                                              "rgen_threesome.hf"};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class HfCorpus : public ::testing::Test {
 protected:
  void SetUp() override {
    FREP_NEED_CORPUS(kCorpus);  // skipped locally, failed in CI (shared_corpus.h)
  }
};

// The two models hfp cannot run either: a published typo in the header, and a call of the R
// package's callback. Each must fail with an error that names the place and says why.
const std::map<std::string, std::string> kExpectedErrors = {
    {"doc_hfobj_sphere_bourke.hf", "doc_hfobj_sphere_bourke.hf:1:8: error: expected 'x'"},
    {"talk_hfR.hf", "talk_hfR.hf:3:12: error: 'hfR' is not supported: in the R package"},
};

TEST_F(HfCorpus, EveryModelCompiles) {
  int models = 0;
  for (const auto& e : fs::directory_iterator(kCorpus)) {
    if (e.path().extension() != ".hf") continue;
    ++models;
    std::string name = e.path().filename().string();
    CompileResult r = compile(slurp(e.path()), name);
    auto bad = kExpectedErrors.find(name);
    if (bad == kExpectedErrors.end()) {
      EXPECT_TRUE(r.ok) << name << ":\n" << allDiagnostics(r);
    } else {
      EXPECT_FALSE(r.ok) << name;
      EXPECT_EQ(allDiagnostics(r).rfind(bad->second, 0), 0u) << allDiagnostics(r);
    }
  }
  EXPECT_EQ(models, 53);
}

TEST_F(HfCorpus, EveryReferenceValue) {
  std::vector<Reference> refs;
  for (const Reference& r : readTable(kCorpus / "expected.tsv"))
    if (!kExponentQuirk.count(r.file)) refs.push_back(r);
  std::vector<Reference> fixed = readTable(kCorpus / "expected_exponent_fixed.tsv");
  refs.insert(refs.end(), fixed.begin(), fixed.end());
  ASSERT_EQ(refs.size(), 471u);

  std::map<std::string, Model> cache;
  int failures = 0;
  for (const Reference& ref : refs) {
    std::string key = ref.file + "|" + ref.object + "|";
    for (double p : ref.params) key += std::to_string(p) + ",";
    if (!cache.count(key)) {
      CompileOptions opt;
      opt.object = ref.object;
      opt.params = ref.params;
      CompileResult r = compile(slurp(kCorpus / ref.file), ref.file, opt);
      ASSERT_TRUE(r.ok) << ref.file << "\n" << allDiagnostics(r);
      ASSERT_EQ(r.model.objectName, ref.object) << ref.file;
      cache[key] = r.model;
    }
    double got = evalModel(cache[key], ref.x);
    double tol = 1e-9 * std::max(1.0, std::fabs(ref.value));
    if (!(std::fabs(got - ref.value) <= tol)) {
      ++failures;
      ADD_FAILURE() << ref.file << " (" << ref.object << ") at line " << ref.line << ": got "
                    << got << ", hfp " << ref.value;
    }
  }
  EXPECT_EQ(failures, 0);
}

}  // namespace
}  // namespace frep::lang::testing
