#include "allocator_tuning.h"

#include <malloc.h>

namespace frep::farm {

void keepFreedMemory() {
  constexpr int kBytes = 256 << 20;  // above any one vector of a brick at the job limits
  mallopt(M_MMAP_THRESHOLD, kBytes);
  mallopt(M_TRIM_THRESHOLD, kBytes);
}

}  // namespace frep::farm
