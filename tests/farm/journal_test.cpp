// The journal reader against damaged files (issue 15): a corrupted length field never allocates
// more than the file holds; records after the damage are dropped, those before are replayed.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include "frep/farm/crc32.h"
#include "frep/master/journal.h"

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

// The journal is opened as -O is (O_NOFOLLOW, regular files only): a symlink planted at its
// name is neither followed nor truncated (before: fopen("wb") truncated the link's target), a
// FIFO does not block the master, with or without resume.
TEST(Journal, NeverOpensThroughASymlinkOrASpecialFile) {
  const std::string dir = testing::TempDir() + "journal_nofollow_" + std::to_string(::getpid()) + "/";
  ::mkdir(dir.c_str(), 0755);
  const std::string victim = dir + "victim", link = dir + "link.journal", fifo = dir + "fifo.journal";
  std::ofstream(victim) << "precious";
  ASSERT_EQ(::symlink(victim.c_str(), link.c_str()), 0);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  for (const std::string& p : {link, fifo})
    for (bool resume : {false, true})
      EXPECT_THROW(Journal(p, 42, resume, [](uint64_t, const std::string&) {}), frep::farm::JournalIoError)
          << p << " resume " << resume;
  EXPECT_EQ(readAll(victim), "precious");
  // A dangling symlink is not created through either.
  const std::string dangling = dir + "dangling.journal";
  ASSERT_EQ(::symlink((dir + "made").c_str(), dangling.c_str()), 0);
  EXPECT_THROW(Journal(dangling, 42, false, nullptr), frep::farm::JournalIoError);
  struct stat st;
  EXPECT_NE(::lstat((dir + "made").c_str(), &st), 0);
  // A regular journal still works.
  EXPECT_EQ((writeJournal(dir + "ok.journal", 2), replayed(dir + "ok.journal")), 2);
}

// Records added from several threads at once (the master's decode threads) each take their own
// stretch of the file: all replay, intact. A resumed journal with a torn last record writes its
// new records right after the last good one.
TEST(Journal, RecordsAddedConcurrentlyAndAfterAResumeAllReplay) {
  const std::string path = "/tmp/frep_journal_concurrent_" + std::to_string(getpid()) + ".journal";
  std::remove(path.c_str());
  const int threads = 4, perThread = 50;
  auto payloadOf = [](uint64_t brick) { return std::string(1000 + brick, char('a' + brick % 26)); };
  {
    Journal j(path, 42, false, nullptr);
    std::vector<std::thread> ts;
    for (int t = 0; t < threads; ++t)
      ts.emplace_back([&, t] {
        for (int r = 0; r < perThread; ++r) j.append(uint64_t(t * perThread + r), payloadOf(uint64_t(t * perThread + r)));
      });
    for (auto& t : ts) t.join();
  }
  const std::string whole = readAll(path);
  ASSERT_EQ(whole.size(), size_t(12 + threads * perThread * 20) + [&] {
    size_t n = 0;
    for (uint64_t b = 0; b < uint64_t(threads * perThread); ++b) n += payloadOf(b).size();
    return n;
  }());
  std::set<uint64_t> seen;
  auto replay = [&] {
    seen.clear();
    Journal j(path, 42, true, [&](uint64_t brick, const std::string& payload) {
      EXPECT_EQ(payload, payloadOf(brick));
      EXPECT_TRUE(seen.insert(brick).second) << "brick " << brick << " replayed twice";
    });
  };
  replay();
  EXPECT_EQ(seen.size(), size_t(threads * perThread));
  // Tear the last record, resume (it is dropped), add two records: they follow the good ones.
  ASSERT_EQ(truncate(path.c_str(), off_t(whole.size() - 10)), 0);
  uint64_t torn = 0;
  {
    std::set<uint64_t> before;
    Journal j(path, 42, true, [&](uint64_t brick, const std::string&) { before.insert(brick); });
    EXPECT_EQ(before.size(), size_t(threads * perThread - 1));
    for (uint64_t b = 0; b < uint64_t(threads * perThread); ++b)
      if (!before.count(b)) torn = b;
    j.append(torn, payloadOf(torn));
    j.append(1000, payloadOf(1000));
  }
  replay();
  EXPECT_EQ(seen.size(), size_t(threads * perThread + 1));
  EXPECT_TRUE(seen.count(torn) && seen.count(1000));
  std::remove(path.c_str());
}

// The master keeps a merged brick's payload in the journal (docs/farm.md, "Back-pressure"):
// add says where it is, read gives back exactly those bytes, and a read past what was written
// is an I/O error, never a short buffer.
TEST(Journal, ReadGivesBackEachPayloadWhereAddPutIt) {
  const std::string path = ::testing::TempDir() + "read_back.journal";
  std::remove(path.c_str());
  Journal j(path, 42, false, nullptr);
  std::vector<std::string> payloads{"first", std::string(70000, 'x'), "", "last one"};
  payloads[1][12345] = 'y';
  std::vector<uint64_t> at;
  for (size_t i = 0; i < payloads.size(); ++i) at.push_back(j.append(i, payloads[i]));
  for (size_t i = 0; i < payloads.size(); ++i) {
    std::string back(payloads[i].size(), '\0');
    j.read(at[i], back.data(), back.size());
    EXPECT_EQ(back, payloads[i]) << i;
  }
  std::string past(16, '\0');
  EXPECT_THROW(j.read(at.back() + 4, past.data(), past.size()), frep::farm::JournalIoError);
  std::remove(path.c_str());
}

// The journal allocates the file's blocks ahead of its records in 64 MiB steps (Journal::add):
// records across steps and one larger than a step replay whole, and the file's size is what
// was written, not what was allocated (so a resume never reads the blocks past the records).
TEST(Journal, RecordsAcrossTheBlocksAllocatedAheadReplayAndTheSizeIsWhatWasWritten) {
  const std::string path = ::testing::TempDir() + "allocated_ahead.journal";
  std::remove(path.c_str());
  std::vector<std::string> payloads{std::string(40 << 20, 'a'), std::string(70 << 20, 'b'), std::string(1000, 'c')};
  payloads[1][(70 << 20) - 1] = 'z';
  size_t written = 12;
  {
    Journal j(path, 42, false, nullptr);
    for (size_t i = 0; i < payloads.size(); ++i) {
      j.append(i, payloads[i]);
      written += 20 + payloads[i].size();
      struct stat st {};
      ASSERT_EQ(stat(path.c_str(), &st), 0);
      EXPECT_EQ(uint64_t(st.st_size), written) << "after record " << i;
    }
  }
  size_t n = 0;
  Journal j(path, 42, true, [&](uint64_t brick, const std::string& payload) {
    ASSERT_LT(brick, payloads.size());
    EXPECT_TRUE(payload == payloads[brick]) << "record " << brick;
    ++n;
  });
  EXPECT_EQ(n, payloads.size());
  j.append(3, "after the resume");
  struct stat st {};
  ASSERT_EQ(stat(path.c_str(), &st), 0);
  EXPECT_EQ(uint64_t(st.st_size), written + 20 + 16);
  std::remove(path.c_str());
}

// The master journals a loop turn's results in one call (Journal::addAll): a batch of more
// records than one pwritev takes (512), empty payloads among them, lands byte for byte as the
// same records added one by one would (the file compared whole), each `at` where read finds
// its payload, and a batch added after a single record and a resume follows it.
TEST(Journal, RecordsAddedInABatchAreTheRecordsAddedOneByOne) {
  const std::string dir = ::testing::TempDir();
  const std::string single = dir + "one_by_one.journal", batched = dir + "batched.journal";
  std::remove(single.c_str());
  std::remove(batched.c_str());
  std::vector<std::string> payloads;
  for (size_t i = 0; i < 1300; ++i)
    payloads.push_back(i % 97 == 5 ? std::string() : std::string(100 + (i * 37) % 3000, char('a' + i % 26)));
  std::vector<Journal::Record> records;
  for (size_t i = 0; i < payloads.size(); ++i)
    records.push_back(
        {i, payloads[i].data(), payloads[i].size(), frep::farm::crc32Of(payloads[i].data(), payloads[i].size()), 0});
  {
    Journal one(single, 42, false, nullptr);
    for (size_t i = 0; i < payloads.size(); ++i) one.append(i, payloads[i]);
    Journal all(batched, 42, false, nullptr);
    all.addAll(records.data(), 1);  // a batch of one, then the rest in one call
    all.addAll(records.data() + 1, records.size() - 1);
    for (size_t i = 0; i < payloads.size(); ++i) {
      std::string back(payloads[i].size(), '\0');
      all.read(records[i].at, back.data(), back.size());
      EXPECT_TRUE(back == payloads[i]) << "record " << i;
    }
  }
  EXPECT_TRUE(readAll(single) == readAll(batched));
  {
    Journal j(batched, 42, true, [](uint64_t, const std::string&) {});
    Journal::Record more[2] = {{5000, "x", 1, frep::farm::crc32Of("x", 1), 0},
                               {5001, "yz", 2, frep::farm::crc32Of("yz", 2), 0}};
    j.addAll(more, 2);
  }
  size_t n = 0;
  Journal j(batched, 42, true, [&](uint64_t brick, const std::string& payload) {
    if (brick < payloads.size()) EXPECT_TRUE(payload == payloads[brick]) << "record " << brick;
    else EXPECT_EQ(payload, brick == 5000 ? "x" : "yz");
    ++n;
  });
  EXPECT_EQ(n, payloads.size() + 2);
  std::remove(single.c_str());
  std::remove(batched.c_str());
}
