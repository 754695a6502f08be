// adviseHugePages (worker/allocator_tuning.h), the hint the allocator policy gives the heap.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "allocator_tuning.h"

using frep::farm::adviseHugePages;

// adviseHugePages is a hint on the whole 2 MiB pages inside a range: any range (empty, short,
// unaligned, heap or mapped) is accepted and its bytes are left as they are.
TEST(AllocatorTuning, AdviseHugePagesKeepsAnyBufferIntact) {
  adviseHugePages(nullptr, 0);
  std::vector<char> small(100, 'a');
  adviseHugePages(small.data(), small.size());
  EXPECT_EQ(std::string(small.begin(), small.end()), std::string(100, 'a'));
  std::vector<uint32_t> big(3 << 20);  // 12 MiB, an unaligned start
  for (size_t i = 0; i < big.size(); ++i) big[i] = uint32_t(i * 2654435761u);
  adviseHugePages(reinterpret_cast<char*>(big.data()) + 3, big.size() * 4 - 7);
  for (size_t i = 0; i < big.size(); ++i) ASSERT_EQ(big[i], uint32_t(i * 2654435761u));
  std::vector<uint32_t> fresh;
  fresh.reserve(big.size());
  adviseHugePages(fresh.data(), big.size() * 4);  // before its first write
  fresh.assign(big.begin(), big.end());
  EXPECT_EQ(fresh, big);
}

TEST(AllocatorTuning, PolicyIsReportedOnceApplied) {
  // In a child process: the policy is process-wide (the master's mesh merge reads the flag to
  // keep the freed pieces instead of trimming the heap).
  EXPECT_EXIT(
      {
        if (frep::farm::allocatorPolicyApplied()) std::exit(1);
        frep::farm::applyAllocatorPolicy();
        std::exit(frep::farm::allocatorPolicyApplied() ? 0 : 2);
      },
      ::testing::ExitedWithCode(0), "");
}
