// One brick of a job: the unit of work a worker computes and the master merges. The same code
// runs in workers and in the master's in-process mode (--workers 0), which is why the farm's
// output is bit-identical to the in-process run. Compiling the job's model is job_model.h's.
#pragma once

#include <array>
#include <cstdint>

#include "frep/farm/brick_codec.h"
#include "frep/farm/crc32.h"
#include "frep/farm/job.h"
#include "farm.pb.h"
#include "frep/meshing/mesh.h"
#include "frep/render/raycast.h"
#include "frep/sampling/sample.h"
#include "frep/worker/job_model.h"

namespace frep::farm {

// Computes the region [lo, hi) of the job's grid: samples it ("sample"), meshes its cells
// ("mesh", core meshRegion with the job's MeshSpec) or casts its pixels' rays ("render",
// castRegion; the region must be made of whole kRenderTile tiles). threads: 0 = all cores; never changes the
// result.
BrickOutput computeBrick(const TapePtr& tape, const JobSpec& job, const std::array<int32_t, 3>& lo,
                         const std::array<int32_t, 3>& hi, int threads);

}  // namespace frep::farm
