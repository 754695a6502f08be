// The journal reader against damaged files (issue 15): a corrupted length field never allocates
// more than the file holds; records after the damage are dropped, those before are replayed.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "journal.h"

using frep::farm::Journal;

namespace {

std::string readAll(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string writeJournal(const std::string& path, int records) {
  std::remove(path.c_str());
  Journal j(path, 42, false, nullptr);
  for (int r = 0; r < records; ++r) j.append(uint64_t(r), std::string(1000 + r, char('a' + r)));
  j.flush();
  return readAll(path);
}

int replayed(const std::string& path) {
  int n = 0;
  Journal j(path, 42, true, [&](uint64_t brick, const std::string& payload) {
    EXPECT_EQ(payload, std::string(1000 + brick, char('a' + brick)));
    ++n;
  });
  return n;
}

}  // namespace

TEST(Journal, CorruptedLengthFieldsAllocateNothingLarge) {
  const std::string path = testing::TempDir() + "journal_length_test";
  const std::string good = writeJournal(path, 3);
  const size_t record = 8 + 4 + 8;
  const size_t secondSize = 12 + record + 1000 + 8 + 4;  // the second record's length field
  // The address space is capped at 1 GiB more than now: a 16 GiB std::string would throw.
  rlimit old{};
  ::getrlimit(RLIMIT_AS, &old);
  for (uint64_t bad : {uint64_t(1) << 34, uint64_t(1) << 33, uint64_t(1) << 40, ~uint64_t(0), uint64_t(5000)}) {
    std::string b = good;
    std::memcpy(&b[secondSize], &bad, 8);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << b;
    rlimit cap = old;
    cap.rlim_cur = rlim_t(3) << 30;  // well below any damaged length above but 5000
    if (old.rlim_max == RLIM_INFINITY || old.rlim_max >= cap.rlim_cur) ::setrlimit(RLIMIT_AS, &cap);
    int n = -1;
    EXPECT_NO_THROW(n = replayed(path)) << bad;
    ::setrlimit(RLIMIT_AS, &old);
    EXPECT_EQ(n, 1) << "only the record before the damage, length " << bad;
    EXPECT_EQ(readAll(path).size(), 12 + record + 1000) << "the journal is cut at the last good record";
  }
  std::remove(path.c_str());
}

TEST(Journal, EveryTruncationReplaysTheWholeRecordsBeforeIt) {
  const std::string path = testing::TempDir() + "journal_truncation_test";
  const std::string good = writeJournal(path, 3);
  size_t ends[4] = {12, 12 + 20 + 1000, 12 + 40 + 2001, good.size()};
  for (size_t n = 12; n <= good.size(); n += 7) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << good.substr(0, n);
    int whole = 0;
    while (whole < 3 && ends[whole + 1] <= n) ++whole;
    EXPECT_EQ(replayed(path), whole) << n;
  }
  std::remove(path.c_str());
}
