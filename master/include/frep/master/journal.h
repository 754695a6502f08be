// The master's journal: every merged brick is appended (id, crc, payload), so a master that
// crashed or was stopped can resume without recomputing what it had. Append-only; a torn last
// record (crash mid-write) is detected by its length and CRC and dropped on resume.
#pragma once

#include <cstdint>
#include <atomic>
#include <cstdio>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>

namespace frep::farm {

// The largest record replayed (a brick's payload); a longer length field is corruption, and so is
// one longer than what remains of the file: the record and everything after it are dropped.
constexpr uint64_t kMaxJournalRecord = uint64_t(256) << 20;

// Records whose "brick" is one of these are not bricks (a master of an older release ignores
// them, as any id beyond its bricks). kJournalRevoke, payload a u64 brick id: the records of that
// brick before it are void (its worker was convicted of forging, or the record was never
// merged); a replay forgets the brick and merges the brick's next record, if any.
// kJournalVerifySeed, payload a u64: the verification sample's seed (FarmOptions::verifySeed),
// so that a resumed job checks the same bricks.
constexpr uint64_t kJournalRevoke = ~uint64_t(0);
constexpr uint64_t kJournalVerifySeed = ~uint64_t(0) - 1;

// The journal's file cannot be opened, written or truncated (a full disk, EFBIG, EIO): an I/O
// error (frep exit 3), not a farm error.
struct JournalIoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Journal {
 public:
  // Opens path for a job. With resume, replays the records of the same job through onRecord
  // and keeps appending after the last good one; a journal of another job is an error
  // (std::runtime_error). Without resume, any old journal is replaced.
  Journal(const std::string& path, uint64_t jobId, bool resume,
          const std::function<void(uint64_t brick, const std::string& payload)>& onRecord);
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  // Appends a record (its payload's CRC-32 already known) straight to the kernel (pwrite), so
  // a killed master loses none of it. Safe to call from several threads at once: each record
  // takes its own stretch of the file (their order in it does not matter); they write in turn.
  // Returns where the payload starts in the file (for read).
  uint64_t add(uint64_t brick, const void* payload, size_t size, uint32_t crc);
  // A record for addAll: what add takes; `at` is set to where its payload starts in the file.
  struct Record {
    uint64_t brick = 0;
    const void* payload = nullptr;
    size_t size = 0;
    uint32_t crc = 0;
    uint64_t at = 0;
  };
  // Appends `n` records as add does, one after another in one stretch of the file and with as
  // few system calls as the kernel allows (one pwritev of up to 512 records): what the master
  // received in one loop turn. Each record is complete in the kernel when this returns.
  void addAll(Record* records, size_t n);
  uint64_t append(uint64_t brick, const std::string& payload);  // add, computing the CRC
  // Reads back `size` bytes at `offset` (a payload add placed there): the master keeps a merged
  // brick's payload here, in the page cache, rather than a second copy in its own memory.
  // Throws JournalIoError if the file is shorter or unreadable. Safe from several threads.
  void read(uint64_t offset, void* into, size_t size) const;
  void flush();  // to the disk (fdatasync)
  void remove(); // after the output was written: the journal is no longer needed
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  FILE* file_ = nullptr;
  std::atomic<uint64_t> end_{0};  // where the next record goes
  std::mutex writeMutex_;         // one writer at a time (add)
  // The file's blocks allocated ahead of the records up to here (reserve; under writeMutex_).
  void reserve(uint64_t end);
  uint64_t reserved_ = 0;
  bool reserveFailed_ = false;
};

}  // namespace frep::farm
