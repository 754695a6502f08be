// Writes the fuzz targets' seed corpora from the code that makes the real inputs, so the seeds
// follow the formats: a worker's brick payloads (FRB2, raw and simplified FRM4) and a task envelope
// for `payload`, a journal of them for `journal`, frep sample's sealed .vdb for `vdb`. The .hf seeds are examples/ itself. Run by
// run_fuzz.sh: fuzz_seeds DIR writes DIR/<target>/.
#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "frep/worker/brick.h"
#include "frep/io/vdb_writer.h"
#include "frep/master/journal.h"

namespace {

const char* kModel = R"(my_model(x[3], a[1]) {
  my_model = ((0.7 - abs(x[1])) & (0.6 - abs(x[2])) & (0.5 - abs(x[3]))) | (0.9 - sqrt(x[1]^2 + x[2]^2 + (x[3] - 0.8)^2));
})";

void put(const std::string& dir, const std::string& name, char kind, const std::string& bytes) {
  ::mkdir(dir.c_str(), 0755);
  std::ofstream(dir + "/" + name, std::ios::binary) << std::string(1, kind) << bytes;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) return std::fprintf(stderr, "usage: fuzz_seeds DIR\n"), 2;
  const std::string dir = argv[1];
  ::mkdir(dir.c_str(), 0755);
  using namespace frep;
  farm::JobSpec job;
  job.set_model_source(kModel);
  job.set_model_name("seed.hf");
  job.set_band(2);
  const GridSpec grid = GridSpec::fromBounds({-1.5, -1.5, -1.5}, {1.5, 1.5, 1.5}, 20);
  farm::setGrid(job, grid);
  const TapePtr tape = farm::compileJobModel(job);
  const std::array<int32_t, 3> lo{0, 0, 0}, hi{16, 16, 16};

  const std::string payloads = dir + "/payload", journals = dir + "/journal", vdbs = dir + "/vdb";
  const std::string brick = farm::encodeBrick(farm::computeBrick(tape, job, lo, hi, 1));
  put(payloads, "frb2_brick", 0, brick);
  farm::JobSpec meshJob = job;
  meshJob.set_operation("mesh");
  const std::string raw = farm::encodeMeshPiece(farm::computeBrick(tape, meshJob, lo, {8, 8, 8}, 1).piece);
  put(payloads, "frm4_raw", 1, raw);
  meshJob.mutable_mesh()->set_tolerance(0.5);
  const std::string simplified = farm::encodeMeshPiece(farm::computeBrick(tape, meshJob, lo, {8, 8, 8}, 1).piece);
  put(payloads, "frm4_simplified", 1, simplified);
  farm::Envelope welcome;  // protocol 2: the job once per connection, tasks name it by id
  welcome.set_job_id(farm::jobIdOf(job));
  welcome.mutable_welcome()->set_heartbeat_ms(500);
  *welcome.mutable_welcome()->mutable_job() = job;
  put(payloads, "envelope_welcome", 2, welcome.SerializeAsString());
  farm::Envelope task;
  task.set_job_id(farm::jobIdOf(job));
  task.mutable_task()->set_brick_id(3);
  for (int a = 0; a < 3; ++a) task.mutable_task()->add_lo(lo[size_t(a)]), task.mutable_task()->add_hi(hi[size_t(a)]);
  put(payloads, "envelope_task", 2, task.SerializeAsString());

  ::mkdir(journals.c_str(), 0755);
  {
    const std::string path = journals + "/two_records";
    farm::Journal j(path, 42, false, nullptr);  // fuzz_journal replays job 42
    j.append(0, brick);
    j.append(5, raw);
  }

  ::mkdir(vdbs.c_str(), 0755);
  SampleOptions so;
  so.bandVoxels = 2;
  io::VdbMetadata meta;
  meta.gridName = "my_model";
  const std::string sealed = vdbs + "/sealed.vdb.tmp";
  std::ofstream(sealed).close();  // writeLevelSet writes into an existing file (AtomicOutput's)
  io::writeLevelSet(sealed, sample(tape, GridSpec::fromBounds({-1.5, -1.5, -1.5}, {1.5, 1.5, 1.5}, 12), so), meta);
  std::ifstream in(sealed, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::remove(sealed.c_str());
  put(vdbs, "sealed", 0, bytes);
  put(vdbs, "sealed_resealing", 1, bytes);  // re-sealed after mutation with FREP_FUZZ_VDB_CRAFTED=1
  return 0;
}
