#include "frep/master/journal.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "frep/farm/crc32.h"

namespace frep::farm {

namespace {
constexpr char kMagic[4] = {'F', 'R', 'J', '1'};
// A record is one brick's payload: never more than a frame the master accepts from a worker.
constexpr uint64_t kMaxRecord = kMaxJournalRecord;
constexpr long kRecordHeader = 8 + 4 + 8;  // brick, crc, size
constexpr uint64_t kReserveStep = uint64_t(64) << 20;  // blocks allocated ahead (Journal::reserve)

// Opens the journal as -O's policy does (io/src/atomic_output.cpp): only a regular file, never
// through a symbolic link (a planted `out.vdb.journal -> ~/.bashrc` would be truncated), never
// blocking on a FIFO (O_NONBLOCK; fstat then refuses it). nullptr with errno ENOENT when absent
// and not created; any other failure is a JournalIoError naming what the path is.
FILE* openJournal(const std::string& path, int flags, const char* mode) {
  auto notRegular = [&](const char* what) {
    return JournalIoError("journal " + path + " is " + what + "; frep keeps its journal only in a regular file");
  };
  int fd = ::open(path.c_str(), flags | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
  struct stat st;
  if (fd < 0) {
    if (errno == ENOENT && !(flags & O_CREAT)) return nullptr;
    const int err = errno;
    if (::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode)) throw notRegular("a symbolic link");
    if (::lstat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) throw notRegular("not a regular file");
    throw JournalIoError("cannot open journal " + path + ": " + std::strerror(err));
  }
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw notRegular("not a regular file (a FIFO, device, socket or directory)");
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  FILE* f = ::fdopen(fd, mode);
  if (!f) {
    const int err = errno;
    ::close(fd);
    throw JournalIoError("cannot open journal " + path + ": " + std::strerror(err));
  }
  return f;
}
}  // namespace

Journal::Journal(const std::string& path, uint64_t jobId, bool resume,
                 const std::function<void(uint64_t, const std::string&)>& onRecord)
    : path_(path) {
  long goodEnd = 0;
  if (resume) {
    if (FILE* in = openJournal(path, O_RDONLY, "rb")) {
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
    file_ = openJournal(path, O_RDWR, "r+b");  // records go at end_ (pwrite), not O_APPEND; read back (pread)
    if (!file_ || ::ftruncate(fileno(file_), goodEnd) != 0)
      throw JournalIoError("cannot truncate journal " + path + ": " + std::strerror(errno));
  } else {
    file_ = openJournal(path, O_RDWR | O_CREAT | O_TRUNC, "r+b");
    std::fwrite(kMagic, 1, 4, file_);
    std::fwrite(&jobId, sizeof jobId, 1, file_);
  }
  if (std::fflush(file_) != 0 || std::ferror(file_))
    throw JournalIoError("cannot write journal " + path + ": " + std::strerror(errno));
  end_ = goodEnd > 0 ? uint64_t(goodEnd) : uint64_t(sizeof kMagic + sizeof jobId);
  reserved_ = end_;
  flush();
}

Journal::~Journal() {
  if (file_) std::fclose(file_);
}

uint64_t Journal::add(uint64_t brick, const void* payload, size_t size, uint32_t crc) {
  Record r{brick, payload, size, crc, 0};
  addAll(&r, 1);
  return r.at;
}

void Journal::addAll(Record* records, size_t n) {
  // Each call's records get their own stretch of the file, written in one pwritev (a header and
  // a payload per record), one writer at a time: the file system serializes writers to a file
  // anyway (ext4's inode lock), and a writer waiting on our mutex sleeps where one waiting on
  // that lock spins. A batch costs one system call where a record each took one.
  constexpr size_t kPerCall = 512;  // records per pwritev: 2 iovecs each, within IOV_MAX (1024)
  for (size_t from = 0; from < n; from += kPerCall) {
    const size_t count = std::min(kPerCall, n - from);
    Record* batch = records + from;
    std::vector<char> heads(count * kRecordHeader);
    std::vector<struct iovec> parts;
    parts.reserve(2 * count);
    uint64_t total = 0;
    for (size_t i = 0; i < count; ++i) {
      char* head = heads.data() + i * kRecordHeader;
      const uint64_t size64 = batch[i].size;
      std::memcpy(head, &batch[i].brick, 8);
      std::memcpy(head + 8, &batch[i].crc, 4);
      std::memcpy(head + 12, &size64, 8);
      parts.push_back({head, size_t(kRecordHeader)});
      if (batch[i].size) parts.push_back({const_cast<void*>(batch[i].payload), batch[i].size});
      total += uint64_t(kRecordHeader) + batch[i].size;
    }
    const uint64_t at = end_.fetch_add(total);
    for (size_t i = 0, off = 0; i < count; ++i) {
      batch[i].at = at + off + uint64_t(kRecordHeader);
      off += size_t(kRecordHeader) + batch[i].size;
    }
    std::lock_guard<std::mutex> writing(writeMutex_);
    reserve(at + total);
    struct iovec* part = parts.data();
    size_t left = parts.size();
    for (uint64_t done = 0; done < total;) {  // from where a short write stopped
      const ssize_t w = ::pwritev(fileno(file_), part, int(left), off_t(at + done));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) throw JournalIoError("cannot write journal " + path_ + ": " + std::strerror(w < 0 ? errno : ENOSPC));
      done += uint64_t(w);
      for (size_t skip = size_t(w); skip > 0;) {  // past what was written
        if (skip >= part->iov_len) {
          skip -= part->iov_len, ++part, --left;
        } else {
          part->iov_base = static_cast<char*>(part->iov_base) + skip, part->iov_len -= skip, skip = 0;
        }
      }
    }
  }
}

void Journal::reserve(uint64_t end) {
  // Writing into blocks the file system has already allocated costs a third less CPU than
  // allocating them page by page as the writes come (ext4's delayed allocation, measured: 26
  // against 37 us per 151 kB record), so the file's blocks are allocated ahead in large steps.
  // KEEP_SIZE: the file's size is still what was written, so a resume reads only records. A
  // file system that cannot (EOPNOTSUPP) or a full disk just leaves the writes to allocate (and
  // to report ENOSPC themselves).
  if (end <= reserved_ || reserveFailed_) return;
  const uint64_t step = std::max<uint64_t>(kReserveStep, end - reserved_);
  if (::fallocate(fileno(file_), FALLOC_FL_KEEP_SIZE, off_t(reserved_), off_t(step)) != 0) {
    reserveFailed_ = true;
    return;
  }
  reserved_ += step;
}

uint64_t Journal::append(uint64_t brick, const std::string& payload) {
  return add(brick, payload.data(), payload.size(), crc32Of(payload.data(), payload.size()));
}

void Journal::read(uint64_t offset, void* into, size_t size) const {
  char* p = static_cast<char*>(into);
  while (size > 0) {
    const ssize_t r = file_ ? ::pread(fileno(file_), p, size, off_t(offset)) : -1;
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) throw JournalIoError("cannot read back journal " + path_ + ": " + (r < 0 ? std::strerror(errno) : "it is shorter than what was written to it"));
    p += r, size -= size_t(r), offset += uint64_t(r);
  }
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
