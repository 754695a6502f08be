#include "journal.h"

#include <unistd.h>

#include <cstring>
#include <stdexcept>
#include <vector>

#include "brick.h"

namespace frep::farm {

namespace {
constexpr char kMagic[4] = {'F', 'R', 'J', '1'};
// A record is one brick's payload: never more than a frame the master accepts from a worker.
constexpr uint64_t kMaxRecord = kMaxJournalRecord;
constexpr long kRecordHeader = 8 + 4 + 8;  // brick, crc, size
}  // namespace

Journal::Journal(const std::string& path, uint64_t jobId, bool resume,
                 const std::function<void(uint64_t, const std::string&)>& onRecord)
    : path_(path) {
  long goodEnd = 0;
  if (resume) {
    if (FILE* in = std::fopen(path.c_str(), "rb")) {
      char magic[4];
      uint64_t id = 0;
      bool headerOk = std::fread(magic, 1, 4, in) == 4 && std::memcmp(magic, kMagic, 4) == 0 &&
                      std::fread(&id, sizeof id, 1, in) == 1;
      if (!headerOk) {
        std::fclose(in);
        throw std::runtime_error("journal " + path + " is not a frepfarm journal");
      }
      if (id != jobId) {
        std::fclose(in);
        throw std::runtime_error("journal " + path + " belongs to another job (other model, grid or options): "
                                 "remove it or run without --resume");
      }
      goodEnd = std::ftell(in);
      std::fseek(in, 0, SEEK_END);
      const long fileSize = std::ftell(in);
      std::fseek(in, goodEnd, SEEK_SET);
      for (;;) {
        uint64_t brick = 0, size = 0;
        uint32_t crc = 0;
        if (std::fread(&brick, sizeof brick, 1, in) != 1 || std::fread(&crc, sizeof crc, 1, in) != 1 ||
            std::fread(&size, sizeof size, 1, in) != 1)
          break;
        // A damaged length is never trusted with an allocation: it must fit in what is left.
        if (size > kMaxRecord || size > uint64_t(fileSize - goodEnd - kRecordHeader)) break;
        std::string payload(size, '\0');
        if (std::fread(payload.data(), 1, size, in) != size) break;
        if (crc32Of(payload.data(), payload.size()) != crc) break;
        onRecord(brick, payload);
        goodEnd = std::ftell(in);
      }
      std::fclose(in);
    }
  }
  if (goodEnd > 0) {
    if (::truncate(path.c_str(), goodEnd) != 0)
      throw JournalIoError("cannot truncate journal " + path + ": " + std::strerror(errno));
    file_ = std::fopen(path.c_str(), "ab");
  } else {
    file_ = std::fopen(path.c_str(), "wb");
    if (file_) {
      std::fwrite(kMagic, 1, 4, file_);
      std::fwrite(&jobId, sizeof jobId, 1, file_);
    }
  }
  if (!file_) throw JournalIoError("cannot open journal " + path + ": " + std::strerror(errno));
  if (std::fflush(file_) != 0 || std::ferror(file_))
    throw JournalIoError("cannot write journal " + path + ": " + std::strerror(errno));
  flush();
}

Journal::~Journal() {
  if (file_) std::fclose(file_);
}

void Journal::append(uint64_t brick, const std::string& payload) {
  uint32_t crc = crc32Of(payload.data(), payload.size());
  uint64_t size = payload.size();
  bool ok = std::fwrite(&brick, sizeof brick, 1, file_) == 1 && std::fwrite(&crc, sizeof crc, 1, file_) == 1 &&
            std::fwrite(&size, sizeof size, 1, file_) == 1 &&
            std::fwrite(payload.data(), 1, payload.size(), file_) == payload.size();
  // Hand the record to the kernel now: a killed master loses nothing that was merged.
  if (!ok || std::fflush(file_) != 0) throw JournalIoError("cannot write journal " + path_ + ": " + std::strerror(errno));
}

void Journal::flush() {
  if (!file_) return;
  std::fflush(file_);
  ::fdatasync(fileno(file_));
}

void Journal::remove() {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  std::remove(path_.c_str());
}

}  // namespace frep::farm
