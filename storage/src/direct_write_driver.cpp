#include "direct_write_driver.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <new>
#include <vector>

#include "h5_error.h"
#include "piece_writers.h"

namespace tomorig::storage {
namespace {

// Pieces a direct write is split into, written in parallel (the caller writes the last one).
// Measured with dd on the build machine's virtual disk: one 8 MiB request at a time ~0.5-0.7
// GB/s, four 2 MiB requests in flight ~0.8-1.0 GB/s.
constexpr std::size_t kPieces = 4;
constexpr std::size_t kMinPiece = 1 << 20;

std::atomic<std::size_t> g_direct_bytes{0};

struct AlignedFree {
  void operator()(std::byte* p) const noexcept { std::free(p); }
};
using AlignedBuffer = std::unique_ptr<std::byte, AlignedFree>;

// HDF5 allocates this with the driver's open() and hands it back to every callback: the public
// part must come first.
struct DirectFile {
  H5FD_t pub{};
  int fd = -1;         // every read, small writes, the tails of large ones
  int direct_fd = -1;  // O_DIRECT, or -1 when the file system refuses it
  haddr_t eoa = 0;     // end of the space HDF5 has allocated
  haddr_t eof = 0;     // end of the file on disk
  dev_t device = 0;
  ino_t inode = 0;
  // Bounce buffers for frames whose memory is not page-aligned, one per piece.
  std::vector<AlignedBuffer> bounce;
  std::size_t bounce_bytes = 0;
  PieceWriters writers{kPieces - 1};  // the caller writes the last piece itself
};

DirectFile* of(H5FD_t* file) { return reinterpret_cast<DirectFile*>(file); }
const DirectFile* of(const H5FD_t* file) { return reinterpret_cast<const DirectFile*>(file); }

bool write_all(int fd, const std::byte* data, std::size_t size, off_t offset) {
  while (size > 0) {
    const ssize_t n = ::pwrite(fd, data, size, offset);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
    offset += n;
  }
  return true;
}

// Writes [data, data + size) at `offset` through the O_DIRECT descriptor; size and offset are
// page multiples. Data not page-aligned in memory is copied into the bounce buffers first.
// Returns 0 or the errno of a failed piece.
int write_direct(DirectFile& f, const std::byte* data, std::size_t size, off_t offset) {
  const std::size_t pieces = std::clamp<std::size_t>(size / kMinPiece, 1, kPieces);
  const std::size_t piece = (size / pieces + kDirectAlignment - 1) / kDirectAlignment * kDirectAlignment;
  const bool aligned = reinterpret_cast<std::uintptr_t>(data) % kDirectAlignment == 0;
  if (!aligned && piece > f.bounce_bytes) {
    f.bounce.clear();
    for (std::size_t k = 0; k < kPieces; ++k) {
      auto* p = static_cast<std::byte*>(std::aligned_alloc(kDirectAlignment, piece));
      if (p == nullptr) return ENOMEM;
      f.bounce.emplace_back(p);
    }
    f.bounce_bytes = piece;
  }
  auto write_piece = [&f, data, size, offset, piece, aligned](std::size_t k) {
    const std::size_t begin = k * piece;
    if (begin >= size) return 0;
    const std::size_t n = std::min(piece, size - begin);
    const std::byte* source = data + begin;
    if (!aligned) {
      std::memcpy(f.bounce[k].get(), source, n);
      source = f.bounce[k].get();
    }
    return write_all(f.direct_fd, source, n, offset + static_cast<off_t>(begin)) ? 0 : errno;
  };
  return f.writers.run(pieces, write_piece);
}

H5FD_t* open_file(const char* name, unsigned flags, hid_t /*fapl*/, haddr_t maxaddr) {
  if (name == nullptr || *name == '\0' || maxaddr == 0 || maxaddr == HADDR_UNDEF) return nullptr;
  int o_flags = (flags & H5F_ACC_RDWR) ? O_RDWR : O_RDONLY;
  if (flags & H5F_ACC_TRUNC) o_flags |= O_TRUNC;
  if (flags & H5F_ACC_CREAT) o_flags |= O_CREAT;
  if (flags & H5F_ACC_EXCL) o_flags |= O_EXCL;
  const int fd = ::open(name, o_flags | O_CLOEXEC, 0666);
  if (fd < 0) return nullptr;
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    ::close(fd);
    return nullptr;
  }
  auto* f = new (std::nothrow) DirectFile;
  if (f == nullptr) {
    ::close(fd);
    return nullptr;
  }
  f->fd = fd;
  f->eof = static_cast<haddr_t>(st.st_size);
  f->device = st.st_dev;
  f->inode = st.st_ino;
  if (flags & H5F_ACC_RDWR) f->direct_fd = ::open(name, O_WRONLY | O_DIRECT | O_CLOEXEC);  // -1: refused
  return &f->pub;
}

herr_t close_file(H5FD_t* file) {
  DirectFile* f = of(file);
  bool ok = true;
  if (f->direct_fd >= 0) ok = ::close(f->direct_fd) == 0 && ok;
  ok = ::close(f->fd) == 0 && ok;
  delete f;
  return ok ? 0 : -1;
}

int compare(const H5FD_t* a, const H5FD_t* b) {
  const DirectFile* x = of(a);
  const DirectFile* y = of(b);
  if (x->device != y->device) return x->device < y->device ? -1 : 1;
  if (x->inode != y->inode) return x->inode < y->inode ? -1 : 1;
  return 0;
}

herr_t query(const H5FD_t* /*file*/, unsigned long* flags) {
  // The features of HDF5's sec2 driver, SWMR included: this driver writes the same bytes.
  *flags = H5FD_FEAT_AGGREGATE_METADATA | H5FD_FEAT_ACCUMULATE_METADATA | H5FD_FEAT_DATA_SIEVE |
           H5FD_FEAT_AGGREGATE_SMALLDATA | H5FD_FEAT_POSIX_COMPAT_HANDLE | H5FD_FEAT_SUPPORTS_SWMR_IO;
  return 0;
}

haddr_t get_eoa(const H5FD_t* file, H5FD_mem_t /*type*/) { return of(file)->eoa; }

herr_t set_eoa(H5FD_t* file, H5FD_mem_t /*type*/, haddr_t addr) {
  of(file)->eoa = addr;
  return 0;
}

haddr_t get_eof(const H5FD_t* file, H5FD_mem_t /*type*/) { return of(file)->eof; }

herr_t get_handle(H5FD_t* file, hid_t /*fapl*/, void** handle) {
  if (handle == nullptr) return -1;
  *handle = &of(file)->fd;
  return 0;
}

herr_t read_block(H5FD_t* file, H5FD_mem_t /*type*/, hid_t /*dxpl*/, haddr_t addr, size_t size, void* buffer) {
  DirectFile* f = of(file);
  if (addr == HADDR_UNDEF || addr + size > f->eoa) return -1;
  auto* out = static_cast<std::byte*>(buffer);
  auto offset = static_cast<off_t>(addr);
  while (size > 0) {
    const ssize_t n = ::pread(f->fd, out, size, offset);
    if (n < 0) {
      if (errno == EINTR) continue;
      return -1;
    }
    if (n == 0) {  // past the end of the file: HDF5 expects zeros
      std::memset(out, 0, size);
      break;
    }
    out += n;
    size -= static_cast<std::size_t>(n);
    offset += n;
  }
  return 0;
}

herr_t write_block(H5FD_t* file, H5FD_mem_t /*type*/, hid_t /*dxpl*/, haddr_t addr, size_t size,
                   const void* buffer) {
  DirectFile* f = of(file);
  if (addr == HADDR_UNDEF || addr + size > f->eoa) return -1;
  const auto* data = static_cast<const std::byte*>(buffer);
  const std::size_t whole_pages = size / kDirectAlignment * kDirectAlignment;
  std::size_t done = 0;
  if (f->direct_fd >= 0 && size >= kDirectThreshold && addr % kDirectAlignment == 0) {
    const int error = write_direct(*f, data, whole_pages, static_cast<off_t>(addr));
    if (error == 0) {
      done = whole_pages;
      g_direct_bytes.fetch_add(whole_pages, std::memory_order_relaxed);
    } else if (error == EINVAL) {
      // The file system took the O_DIRECT open but not the write: go the ordinary way for good.
      ::close(f->direct_fd);
      f->direct_fd = -1;
    } else {
      return -1;
    }
  }
  if (done < size && !write_all(f->fd, data + done, size - done, static_cast<off_t>(addr + done))) return -1;
  f->eof = std::max<haddr_t>(f->eof, addr + size);
  return 0;
}

herr_t truncate_file(H5FD_t* file, hid_t /*dxpl*/, hbool_t /*closing*/) {
  DirectFile* f = of(file);
  if (f->eoa == f->eof) return 0;
  if (::ftruncate(f->fd, static_cast<off_t>(f->eoa)) != 0) return -1;
  f->eof = f->eoa;
  return 0;
}

herr_t lock_file(H5FD_t* file, hbool_t rw) {
  if (::flock(of(file)->fd, (rw ? LOCK_EX : LOCK_SH) | LOCK_NB) == 0) return 0;
  return errno == ENOSYS ? 0 : -1;  // file systems without locks: HDF5's own drivers carry on too
}

herr_t unlock_file(H5FD_t* file) {
  if (::flock(of(file)->fd, LOCK_UN) == 0) return 0;
  return errno == ENOSYS ? 0 : -1;
}

H5FD_class_t make_class() {
  H5FD_class_t c{};
  c.name = "tomorig-direct-write";
  c.maxaddr = static_cast<haddr_t>(std::numeric_limits<off_t>::max());
  c.fc_degree = H5F_CLOSE_WEAK;
  c.open = open_file;
  c.close = close_file;
  c.cmp = compare;
  c.query = query;
  c.get_eoa = get_eoa;
  c.set_eoa = set_eoa;
  c.get_eof = get_eof;
  c.get_handle = get_handle;
  c.read = read_block;
  c.write = write_block;
  c.truncate = truncate_file;
  c.lock = lock_file;
  c.unlock = unlock_file;
  const H5FD_mem_t map[] = H5FD_FLMAP_DICHOTOMY;
  std::copy(std::begin(map), std::end(map), std::begin(c.fl_map));
  return c;
}

hid_t driver_id() {
  static std::once_flag once;
  static hid_t id = -1;
  std::call_once(once, [] {
    static const H5FD_class_t cls = make_class();
    id = H5FDregister(&cls);
  });
  return id;
}

}  // namespace

void set_direct_write_driver(hid_t fapl) {
  const hid_t id = driver_id();
  h5::check(id, "cannot register", "the direct-write file driver");
  h5::check(H5Pset_driver(fapl, id, nullptr), "cannot configure", "the direct-write file driver");
  h5::check(H5Pset_alignment(fapl, kDirectThreshold, kDirectAlignment), "cannot configure",
            "the file space alignment");
}

std::size_t direct_bytes_written() { return g_direct_bytes.load(std::memory_order_relaxed); }

}  // namespace tomorig::storage
