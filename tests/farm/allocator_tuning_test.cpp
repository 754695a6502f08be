// adviseHugePages (frep/farm/allocator_tuning.h), the hint the allocator policy gives the heap.
#include <gtest/gtest.h>
#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "frep/farm/allocator_tuning.h"

using frep::farm::adviseHugePages;

namespace {

constexpr size_t kHugePage = size_t(2) << 20;

// The fields of /proc/self/smaps for the mapping that holds `p` ("VmFlags", "THPeligible", ...;
// values as the kernel writes them); empty when no mapping holds it.
std::map<std::string, std::string> smapsOf(const void* p) {
  const uintptr_t at = reinterpret_cast<uintptr_t>(p);
  std::ifstream in("/proc/self/smaps");
  std::map<std::string, std::string> fields;
  bool inside = false;
  for (std::string line; std::getline(in, line);) {
    unsigned long long lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-' && line.find(':') > line.find(' ')) {
      if (inside) break;  // the next mapping's header
      inside = lo <= at && at < hi;
      continue;
    }
    const size_t colon = line.find(':');
    if (inside && colon != std::string::npos) {
      const size_t v = line.find_first_not_of(' ', colon + 1);
      fields[line.substr(0, colon)] = v == std::string::npos ? "" : line.substr(v);
    }
  }
  return fields;
}

bool hasFlag(const std::string& vmFlags, const std::string& flag) {
  std::istringstream in(vmFlags);
  for (std::string f; in >> f;)
    if (f == flag) return true;
  return false;
}

// The kernel's transparent huge page mode ("always", "madvise", "never"), or "" without THP.
std::string thpMode() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string all;
  std::getline(in, all);
  const size_t open = all.find('['), close = all.find(']');
  return open == std::string::npos || close == std::string::npos ? "" : all.substr(open + 1, close - open - 1);
}

}  // namespace

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
  // ... and the advice was taken: the first whole 2 MiB page inside is marked MADV_HUGEPAGE
  // (VmFlags "hg"), unless the kernel was built without transparent huge pages at all.
  const char* const inside =
      reinterpret_cast<const char*>((reinterpret_cast<uintptr_t>(big.data()) + 3 + kHugePage - 1) & ~(kHugePage - 1));
  if (thpMode().empty()) std::cout << "not checking the advice: this kernel has no transparent huge pages\n";
  else
    EXPECT_TRUE(hasFlag(smapsOf(inside)["VmFlags"], "hg"))
        << "the advice was not taken: " << smapsOf(inside)["VmFlags"];
  std::vector<uint32_t> fresh;
  fresh.reserve(big.size());
  adviseHugePages(fresh.data(), big.size() * 4);  // before its first write
  fresh.assign(big.begin(), big.end());
  EXPECT_EQ(fresh, big);
}

// The advice is taken: the kernel marks exactly the whole 2 MiB pages inside the range
// MADV_HUGEPAGE (VmFlags "hg" in /proc/self/smaps), not the partial pages at either end, and
// with THP in "always" or "madvise" mode the advised pages are eligible for huge pages
// (THPeligible 1) where the unadvised ones of a "madvise" kernel are not.
TEST(AllocatorTuning, AdviseHugePagesMarksTheWholeHugePagesInside) {
  const std::string mode = thpMode();
  if (mode.empty())
    GTEST_SKIP() << "this kernel has no transparent huge pages (no /sys/kernel/mm/transparent_hugepage)";
  const size_t bytes = 4 * kHugePage;
  char* const map =
      static_cast<char*>(mmap(nullptr, bytes + kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
  ASSERT_NE(map, MAP_FAILED);
  char* const base = reinterpret_cast<char*>((reinterpret_cast<uintptr_t>(map) + kHugePage - 1) & ~(kHugePage - 1));
  ASSERT_FALSE(smapsOf(base).empty()) << "the mapping is not in /proc/self/smaps";
  ASSERT_EQ(smapsOf(base).count("VmFlags"), 1u) << "no VmFlags line in /proc/self/smaps";
  EXPECT_FALSE(hasFlag(smapsOf(base)["VmFlags"], "hg")) << "advised before the call";
  // [base + 1000, base + 4 huge pages - 1000): the two whole pages in the middle only.
  adviseHugePages(base + 1000, bytes - 2000);
  const std::map<std::string, std::string> head = smapsOf(base), middle = smapsOf(base + kHugePage),
                                           last = smapsOf(base + 3 * kHugePage - 1),
                                           tail = smapsOf(base + 3 * kHugePage);
  EXPECT_FALSE(hasFlag(head.at("VmFlags"), "hg")) << "the partial first page was advised";
  EXPECT_TRUE(hasFlag(middle.at("VmFlags"), "hg")) << "the advice was not taken: " << middle.at("VmFlags");
  EXPECT_TRUE(hasFlag(last.at("VmFlags"), "hg")) << "the last whole page was not advised";
  EXPECT_FALSE(hasFlag(tail.at("VmFlags"), "hg")) << "the partial last page was advised";
  if (middle.count("THPeligible")) {  // Linux >= 5.1
    if (mode == "never") {
      std::cout << "THP mode is \"never\": the advice is recorded but gives no huge pages here\n";
    } else {
      EXPECT_EQ(middle.at("THPeligible"), "1") << "THP mode " << mode;
      if (mode == "madvise") EXPECT_EQ(head.at("THPeligible"), "0") << "unadvised memory eligible in madvise mode";
    }
  }
  munmap(map, bytes + kHugePage);
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
