// "mesh" jobs on the farm: the master in this process, real frep-worker processes. The merged
// mesh is the in-process meshGrid's, vertex for vertex and triangle for triangle, for any worker
// count and brick size, through a worker killed mid-job and a resume from a torn journal; the
// mesh payload codec rejects malformed input without reading out of bounds.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "farm_test_util.h"
#include "frep/meshing/mesh_simplify.h"

using namespace farmtest;

namespace {

JobSpec meshJob(int res) { return partJob("mesh", res); }

void expectSameMesh(const Mesh& a, const Mesh& b) {
  ASSERT_GT(a.triangles.size(), 1000u);
  ASSERT_EQ(a.keys, b.keys);
  ASSERT_EQ(a.positions, b.positions);
  ASSERT_EQ(a.normals, b.normals);
  ASSERT_EQ(a.triangles, b.triangles);
}

Mesh direct(const JobSpec& j, int brick = 0) {
  return meshGrid(compileJobModel(j), gridOf(j), {}, brick);
}

}  // namespace

TEST(MeshFarm, ZeroOneAndTwoWorkersGiveMeshGrid) {
  JobSpec j = meshJob(72);
  const Mesh ref = direct(j);
  const MeshStats split = direct(j, 32).stats;  // shared edges are solved once per brick
  for (int w : {0, 1, 2}) {
    SCOPED_TRACE(w);
    FarmOutcome o = runJob(j, fast(w));
    expectSameMesh(ref, o.mesh);
    EXPECT_EQ(o.report.operation, "mesh");
    EXPECT_EQ(o.report.bricks, 27u);
    EXPECT_EQ(o.report.bricksComputed, 27u);
    EXPECT_EQ(o.report.vertices, ref.positions.size());
    EXPECT_EQ(o.report.triangles, ref.triangles.size());
    EXPECT_EQ(o.mesh.stats.rootEvals, split.rootEvals);
    EXPECT_EQ(o.mesh.stats.cellsVisited, split.cellsVisited);
    EXPECT_TRUE(o.report.poisoned.empty());
    EXPECT_NE(o.report.toJson().find("\"vertices\": " + std::to_string(ref.positions.size())), std::string::npos);
  }
  // Other brick sizes through two workers.
  expectSameMesh(ref, runJob(j, fast(2, 16)).mesh);
  JobSpec s = meshJob(48);
  expectSameMesh(direct(s, 8), runJob(s, fast(2, 24)).mesh);
}

TEST(MeshFarm, WorkerKilledMidJobChangesNothing) {
  JobSpec j = meshJob(72);
  const Mesh ref = direct(j);
  MasterThread m(j, fast(0));
  // The steady worker keeps the queue busy past the victim's liveness window (27 x 100 ms), so
  // the victim's brick is requeued as a death, not merely copied as a straggler.
  WorkerProcess steady(m.endpoint(), {slowMs(100)});
  StartedFile victimStarted("mesh_victim");
  WorkerProcess victim(m.endpoint(), {slowMs(400), victimStarted.env()});
  ASSERT_TRUE(victimStarted.wait()) << "the victim never started a brick";  // it holds one now
  kill(victim.pid, SIGKILL);
  victim.wait();
  m.join();
  ASSERT_EQ(m.error, "");
  const FarmOutcome& out = m.outcome;
  expectSameMesh(ref, out.mesh);
  EXPECT_GE(out.report.deadWorkers, 1u);
  EXPECT_GE(out.report.retries, 1u);
}

TEST(MeshFarm, ResumeFromATruncatedJournalRecomputesOnlyTheMissingBricks) {
  JobSpec j = meshJob(72);
  const Mesh ref = direct(j);
  std::string journal =
      std::filesystem::temp_directory_path() / ("frep-mesh-test-" + std::to_string(getpid()) + ".journal");
  FarmOptions o = fast(0);
  o.journalPath = journal;
  FarmOutcome first = runJob(j, o);
  expectSameMesh(ref, first.mesh);
  tearJournal(journal, 10, 7);  // the first 10 records and a torn one
  o.resume = true;
  o.workers = 2;
  FarmOutcome resumed = runJob(j, o);
  expectSameMesh(ref, resumed.mesh);
  EXPECT_EQ(resumed.report.bricksFromJournal, 10u);
  EXPECT_EQ(resumed.report.bricksComputed, 27u - 10u);
  EXPECT_LT(resumed.report.pointEvals, first.report.pointEvals);
  // A sample job cannot resume a mesh job's journal.
  JobSpec sample = j;
  sample.set_operation("sample");
  sample.set_band(3);
  sample.clear_mesh();
  o.workers = 0;
  EXPECT_THROW(runJob(sample, o), std::runtime_error);
  std::filesystem::remove(journal);
}

TEST(MeshFarm, UnknownOperationIsRefused) {
  JobSpec j = meshJob(24);
  j.set_operation("render");
  EXPECT_THROW(runJob(j, fast(0)), std::invalid_argument);
}

TEST(MeshFarm, MeshPayloadCodecRejectsMalformedInput) {
  JobSpec j = meshJob(40);
  MeshPiece piece = meshRegion(compileJobModel(j), gridOf(j), {0, 0, 0}, {32, 32, 32});
  ASSERT_GT(piece.triangles.size(), 100u);
  piece.stats.fallbackEdges = 7;
  std::string s = encodeMeshPiece(piece);
  EXPECT_LT(s.size(), piece.vertices.size() * 56 + piece.triangles.size() * 12);  // compact
  MeshPiece back;
  std::string err;
  ASSERT_TRUE(decodeMeshPiece(s.data(), s.size(), back, &err)) << err;
  EXPECT_EQ(back.regionLo, piece.regionLo);
  ASSERT_EQ(back.vertices.size(), piece.vertices.size());
  for (size_t i = 0; i < piece.vertices.size(); ++i) {
    ASSERT_EQ(back.vertices[i].key, piece.vertices[i].key);
    ASSERT_EQ(back.vertices[i].position, piece.vertices[i].position);
    ASSERT_EQ(back.vertices[i].normal, piece.vertices[i].normal);
  }
  EXPECT_EQ(back.triangles, piece.triangles);
  EXPECT_EQ(back.stats.rootEvals, piece.stats.rootEvals);
  EXPECT_EQ(back.stats.fallbackEdges, 7u);
  // An empty piece round-trips too.
  MeshPiece empty;
  empty.regionLo = {64, 0, 8};
  std::string e = encodeMeshPiece(empty);
  ASSERT_TRUE(decodeMeshPiece(e.data(), e.size(), back, &err)) << err;
  EXPECT_EQ(back.regionLo, empty.regionLo);
  EXPECT_TRUE(back.vertices.empty() && back.triangles.empty());

  EXPECT_FALSE(decodeMeshPiece(s.data(), s.size() - 1, back, &err));  // truncated
  EXPECT_FALSE(decodeMeshPiece("FRM4", 4, back, &err));
  EXPECT_FALSE(decodeMeshPiece("FRM2", 4, back, &err));
  EXPECT_FALSE(decodeMeshPiece((s + "x").data(), s.size() + 1, back, &err));  // trailing
  std::string bad = s;
  bad[0] = 'X';
  EXPECT_FALSE(decodeMeshPiece(bad.data(), bad.size(), back, &err));  // magic (and version)
  bad = s;
  bad[4] = 3;  // region origin x = 3
  EXPECT_FALSE(decodeMeshPiece(bad.data(), bad.size(), back, &err));
  bad = s;
  const uint32_t huge = 0x7fffffff;
  std::memcpy(&bad[4 + 12 + 48], &huge, 4);  // vertex count beyond the size
  EXPECT_FALSE(decodeMeshPiece(bad.data(), bad.size(), back, &err));
  EXPECT_NE(err.find("counts"), std::string::npos) << err;
  // Hand-made pieces: repeated key, out-of-range and degenerate triangles, non-finite values.
  auto twoVertices = [&](EdgeKey k0, EdgeKey k1, std::array<uint32_t, 3> t, double x) {
    MeshPiece p;
    p.vertices.push_back(MeshVertex{k0, {x, 0, 0}, {1, 0, 0}});
    p.vertices.push_back(MeshVertex{k1, {0, 1, 0}, {0, 1, 0}});
    p.vertices.push_back(MeshVertex{k1 + 1, {0, 0, 1}, {0, 0, 1}});
    p.triangles.push_back(t);
    return encodeMeshPiece(p);
  };
  std::string ok = twoVertices(5, 9, {0, 1, 2}, 1);
  EXPECT_TRUE(decodeMeshPiece(ok.data(), ok.size(), back, &err)) << err;
  for (const std::string& m : {twoVertices(9, 9, {0, 1, 2}, 1), twoVertices(5, 9, {0, 1, 3}, 1),
                               twoVertices(5, 9, {0, 1, 1}, 1), twoVertices(5, 9, {0, 1, 2}, NAN)})
    EXPECT_FALSE(decodeMeshPiece(m.data(), m.size(), back, &err));
  const size_t header = 4 + 12 + 48 + 8;  // one vertex, key > 64 bits
  std::string overlong = e.substr(0, header) + std::string(11, char(0xff)) + std::string(48, '\0') + e.substr(header);
  const uint32_t one = 1;
  std::memcpy(&overlong[4 + 12 + 48], &one, 4);
  EXPECT_FALSE(decodeMeshPiece(overlong.data(), overlong.size(), back, &err));
  EXPECT_NE(err.find("overlong"), std::string::npos) << err;
  // A simplified piece carries the simplifier's state: it round-trips bit for bit.
  MeshPiece simplified = piece;
  SimplifyOptions so;
  so.tolerance = 0.1;
  simplifyRegion(simplified, compileJobModel(j), gridOf(j), so, {0, 0, 0}, {32, 32, 32});
  ASSERT_GT(simplified.carry.counters.collapses, 10u);
  ASSERT_FALSE(simplified.carry.vertices.empty());
  ASSERT_EQ(simplified.carry.triangles.size(), simplified.triangles.size());
  std::string sc = encodeMeshPiece(simplified);
  ASSERT_TRUE(decodeMeshPiece(sc.data(), sc.size(), back, &err)) << err;
  EXPECT_EQ(back.triangles, simplified.triangles);
  EXPECT_EQ(back.carry.triangles, simplified.carry.triangles);
  EXPECT_EQ(back.carry.counters.collapses, simplified.carry.counters.collapses);
  EXPECT_EQ(back.carry.counters.modelEvals, simplified.carry.counters.modelEvals);
  ASSERT_EQ(back.carry.vertices.size(), simplified.carry.vertices.size());
  for (size_t i = 0; i < back.carry.vertices.size(); ++i) {
    EXPECT_EQ(back.carry.vertices[i].index, simplified.carry.vertices[i].index);
    EXPECT_EQ(back.carry.vertices[i].quadric, simplified.carry.vertices[i].quadric);
    EXPECT_EQ(back.carry.vertices[i].moved, simplified.carry.vertices[i].moved);
    EXPECT_EQ(back.carry.vertices[i].settled, simplified.carry.vertices[i].settled);
  }
  // The blocks' runs settled vertices (their collapses ran out): the tags travel too.
  EXPECT_TRUE(std::any_of(simplified.carry.vertices.begin(), simplified.carry.vertices.end(),
                          [](const SimplifyCarry::Vertex& v) { return v.settled != 0; }));
  // A carried vertex past the piece, a bad flag, an error level out of range: refused.
  {
    MeshPiece p = simplified;
    p.carry.vertices.back().index = uint32_t(p.vertices.size());
    std::string m = encodeMeshPiece(p);
    EXPECT_FALSE(decodeMeshPiece(m.data(), m.size(), back, &err));
    EXPECT_NE(err.find("carried vertex index"), std::string::npos) << err;
    p = simplified;
    p.carry.vertices[0].moved = 2;
    m = encodeMeshPiece(p);
    EXPECT_FALSE(decodeMeshPiece(m.data(), m.size(), back, &err));
    p = simplified;
    p.carry.triangles[0] = 0x7f;
    m = encodeMeshPiece(p);
    EXPECT_FALSE(decodeMeshPiece(m.data(), m.size(), back, &err));
    EXPECT_NE(err.find("level"), std::string::npos) << err;
  }
  // Random corruption and truncation never crash the decoder (ASan/UBSan builds check the reads)
  // and what it accepts always satisfies mergePieces' preconditions.
  std::mt19937 rng(11);
  std::string small = encodeMeshPiece(meshRegion(compileJobModel(j), gridOf(j), {32, 32, 32}, {40, 40, 40}));
  for (int k = 0; k < 3000; ++k) {
    std::string m = k % 3 == 1 ? small : (k % 3 == 2 ? sc : s);
    for (int c = 0; c < 4; ++c) m[rng() % m.size()] = char(rng());
    if (rng() % 2) m.resize(rng() % (m.size() + 1));
    if (decodeMeshPiece(m.data(), m.size(), back, &err)) {
      EXPECT_NO_THROW(mergePieces({back}));
    }
  }
  // Through the operation's dispatch too.
  BrickOutput b;
  ASSERT_TRUE(decodePayload(Operation::Mesh, s.data(), s.size(), b, &err)) << err;
  EXPECT_EQ(b.stats.pointEvals, piece.stats.samplePointEvals + piece.stats.rootEvals + piece.stats.gradientEvals);
  EXPECT_FALSE(decodePayload(Operation::Sample, s.data(), s.size(), b, &err));
}
