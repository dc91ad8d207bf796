#include "hdf5_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <new>
#include <stdexcept>
#include <vector>

#include "crash_guard.hpp"
#include "diag/error.hpp"
#include "diag/io/input_file.hpp"

namespace diag::hdf5_detail {

// ---- errors ----------------------------------------------------------------------------------

void silence_hdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

std::unique_lock<std::recursive_mutex> hold_hdf5() {
  static std::recursive_mutex mutex;
  // The child has one thread, and the lock it inherited names the parent's thread as holder.
  if (in_guard_child()) return {};
  std::unique_lock<std::recursive_mutex> lock(mutex);
  // Before the library's first use: no closing of the library at exit. A corrupted file can
  // fail H5Fclose and stay half-open (a MAT 7.3 file whose dataset cannot be opened: found by
  // fuzz_mat); the library's exit handler then crashed on it (SIGSEGV in H5F__close_cb), turning
  // the clean refusal, exit 2, into a crash. geardiag closes every file it opens itself and
  // writes through its own file I/O (hdf5_file_bytes), so nothing needs that handler.
  static const bool no_atexit = [] {
    H5dont_atexit();
    return true;
  }();
  (void)no_atexit;
  thread_local bool silenced = false;
  if (!silenced) {
    silence_hdf5();
    silenced = true;
  }
  return lock;
}

std::string hdf5_error_detail() {
  std::string detail;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* err, void* data) -> herr_t {
        if (n == 0 && err->desc != nullptr) *static_cast<std::string*>(data) = err->desc;
        return 0;
      },
      &detail);
  return detail;
}

void throw_hdf5(const std::string& where, const std::string& what) {
  const std::string detail = hdf5_error_detail();
  throw std::runtime_error(
      format_error(where, what, "HDF5 error" + (detail.empty() ? "" : ": " + detail)));
}

namespace {

// ---- the driver ------------------------------------------------------------------------------
//
// A virtual file driver (HDF5's "VFL", H5FDpublic.h) with two modes: reading a file through a
// descriptor opened once (pread, so the descriptor's offset is never shared state), or writing a
// file into a std::string. Bytes past the end of the file read as zeros, as HDF5's sec2 driver
// reads them; its feature flags are sec2's, so a file made here has the bytes sec2 gives it.

struct DriverInfo {
  int fd = -1;                  // reading: the descriptor
  std::string* sink = nullptr;  // writing: the file's bytes
};

struct DriverFile {
  H5FD_t pub;  // first: HDF5 sees a DriverFile as an H5FD_t
  DriverInfo info;
  haddr_t eoa = 0;
  haddr_t eof = 0;
};

// sec2's address limit: what an off_t can address.
constexpr haddr_t kMaxAddr = (haddr_t{1} << (8 * sizeof(off_t) - 1)) - 1;

DriverFile* file_of(H5FD_t* f) { return reinterpret_cast<DriverFile*>(f); }
const DriverFile* file_of(const H5FD_t* f) { return reinterpret_cast<const DriverFile*>(f); }

void* driver_fapl_get(H5FD_t* f) {
  // HDF5 frees the copy with free() (H5MM_xfree) when the driver has no fapl_free.
  void* copy = std::malloc(sizeof(DriverInfo));
  if (copy != nullptr) std::memcpy(copy, &file_of(f)->info, sizeof(DriverInfo));
  return copy;
}

H5FD_t* driver_open(const char*, unsigned flags, hid_t fapl, haddr_t maxaddr) {
  const auto* info = static_cast<const DriverInfo*>(H5Pget_driver_info(fapl));
  if (info == nullptr || maxaddr == 0 || (maxaddr != HADDR_UNDEF && maxaddr > kMaxAddr)) {
    return nullptr;
  }
  if (info->sink == nullptr && (flags & (H5F_ACC_RDWR | H5F_ACC_TRUNC | H5F_ACC_CREAT)) != 0) {
    return nullptr;  // a file read through a descriptor is never written
  }
  auto* f = new (std::nothrow) DriverFile{};
  if (f == nullptr) return nullptr;
  f->info = *info;
  if (f->info.sink != nullptr) {
    if ((flags & H5F_ACC_TRUNC) != 0) f->info.sink->clear();
    f->eof = f->info.sink->size();
  } else {
    struct stat st {};
    if (::fstat(f->info.fd, &st) != 0) {
      delete f;
      return nullptr;
    }
    f->eof = static_cast<haddr_t>(st.st_size);
  }
  return &f->pub;
}

herr_t driver_close(H5FD_t* f) {
  delete file_of(f);
  return 0;
}

// Every open of a file is its own: HDF5 does not share one between opens.
int driver_cmp(const H5FD_t* a, const H5FD_t* b) { return a < b ? -1 : (a > b ? 1 : 0); }

herr_t driver_query(const H5FD_t*, unsigned long* flags) {
  if (flags != nullptr) {
    *flags = H5FD_FEAT_AGGREGATE_METADATA | H5FD_FEAT_ACCUMULATE_METADATA | H5FD_FEAT_DATA_SIEVE |
             H5FD_FEAT_AGGREGATE_SMALLDATA;
  }
  return 0;
}

haddr_t driver_get_eoa(const H5FD_t* f, H5FD_mem_t) { return file_of(f)->eoa; }

herr_t driver_set_eoa(H5FD_t* f, H5FD_mem_t, haddr_t addr) {
  if (addr > kMaxAddr) return -1;
  file_of(f)->eoa = addr;
  return 0;
}

haddr_t driver_get_eof(const H5FD_t* f, H5FD_mem_t) { return file_of(f)->eof; }

herr_t driver_get_handle(H5FD_t* f, hid_t, void** handle) {
  if (handle == nullptr) return -1;
  *handle = &file_of(f)->info.fd;
  return 0;
}

herr_t driver_read(H5FD_t* f, H5FD_mem_t, hid_t, haddr_t addr, std::size_t size, void* buffer) {
  DriverFile& file = *file_of(f);
  if (addr == HADDR_UNDEF || addr > kMaxAddr || size > kMaxAddr - addr) return -1;
  auto* out = static_cast<unsigned char*>(buffer);
  if (file.info.sink != nullptr) {
    const std::string& bytes = *file.info.sink;
    const std::size_t have = addr < bytes.size() ? std::min(size, bytes.size() - addr) : 0;
    if (have > 0) std::memcpy(out, bytes.data() + addr, have);
    std::memset(out + have, 0, size - have);
    return 0;
  }
  while (size > 0) {
    const ssize_t n = ::pread(file.info.fd, out, size, static_cast<off_t>(addr));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return -1;
    if (n == 0) {
      std::memset(out, 0, size);  // past the end of the file: zeros, as sec2
      break;
    }
    out += n;
    addr += static_cast<haddr_t>(n);
    size -= static_cast<std::size_t>(n);
  }
  return 0;
}

herr_t driver_write(H5FD_t* f, H5FD_mem_t, hid_t, haddr_t addr, std::size_t size,
                    const void* buffer) {
  DriverFile& file = *file_of(f);
  if (file.info.sink == nullptr) return -1;
  if (addr == HADDR_UNDEF || addr > kMaxAddr || size > kMaxAddr - addr) return -1;
  std::string& bytes = *file.info.sink;
  try {
    if (bytes.size() < addr + size) bytes.resize(static_cast<std::size_t>(addr + size), '\0');
  } catch (const std::exception&) {
    return -1;
  }
  std::memcpy(bytes.data() + addr, buffer, size);
  file.eof = std::max<haddr_t>(file.eof, addr + size);
  return 0;
}

herr_t driver_truncate(H5FD_t* f, hid_t, hbool_t) {
  DriverFile& file = *file_of(f);
  if (file.info.sink == nullptr || file.eoa == file.eof) return 0;
  try {
    file.info.sink->resize(static_cast<std::size_t>(file.eoa), '\0');
  } catch (const std::exception&) {
    return -1;
  }
  file.eof = file.eoa;
  return 0;
}

H5FD_class_t make_driver_class() {
  H5FD_class_t c{};
  c.name = "geardiag_descriptor";
  c.maxaddr = kMaxAddr;
  c.fc_degree = H5F_CLOSE_WEAK;
  c.fapl_size = sizeof(DriverInfo);
  c.fapl_get = driver_fapl_get;
  c.open = driver_open;
  c.close = driver_close;
  c.cmp = driver_cmp;
  c.query = driver_query;
  c.get_eoa = driver_get_eoa;
  c.set_eoa = driver_set_eoa;
  c.get_eof = driver_get_eof;
  c.get_handle = driver_get_handle;
  c.read = driver_read;
  c.write = driver_write;
  c.truncate = driver_truncate;
  const H5FD_mem_t map[] = H5FD_FLMAP_DICHOTOMY;
  std::memcpy(c.fl_map, map, sizeof map);
  return c;
}

// The driver's identifier, registered once per library session (again should the library have
// been closed and reopened). Called with the library held (hold_hdf5).
hid_t driver_id() {
  static const H5FD_class_t cls = make_driver_class();
  static hid_t id = -1;
  if (id < 0 || H5Iis_valid(id) <= 0) id = H5FDregister(&cls);
  return id;
}

// ---- the structure check ---------------------------------------------------------------------

std::string size_text(std::uint64_t bytes) { return std::to_string(bytes) + " bytes"; }

[[noreturn]] void refuse(const std::string& where, const std::string& what,
                         const std::string& reason) {
  throw InputError(format_error(where, what, reason));
}

void check_dataset(hid_t file, const std::string& path, const std::string& where,
                   std::uint64_t file_size) {
  Hid ds(H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) refuse(where, path, "cannot be opened (corrupted file?)");
  Hid dcpl(H5Dget_create_plist(ds.get()), H5Pclose);
  Hid type(H5Dget_type(ds.get()), H5Tclose);
  Hid space(H5Dget_space(ds.get()), H5Sclose);
  if (!dcpl.valid() || !type.valid() || !space.valid()) {
    refuse(where, path, "cannot be read (corrupted file?)");
  }
  const H5D_layout_t layout = H5Pget_layout(dcpl.get());
  if (layout == H5D_VIRTUAL) {
    refuse(where, path,
           "is a virtual dataset (its data would come from other files); a file must hold its "
           "data itself");
  }
  const int external = H5Pget_external_count(dcpl.get());
  if (external != 0) {
    refuse(where, path,
           "keeps its data in external files (HDF5 external storage); a file must hold its data "
           "itself");
  }
  if (layout != H5D_CONTIGUOUS && layout != H5D_CHUNKED && layout != H5D_COMPACT) {
    refuse(where, path, "has an unknown storage layout (corrupted file?)");
  }
  // Variable-length values live in the file's heaps, each bounded by the file itself.
  if (H5Tdetect_class(type.get(), H5T_VLEN) > 0 || H5Tis_variable_str(type.get()) > 0) return;
  const hssize_t points = H5Sget_simple_extent_npoints(space.get());
  const std::size_t element = H5Tget_size(type.get());
  if (points < 0 || element == 0) refuse(where, path, "cannot be read (corrupted file?)");
  if (points == 0) return;
  const auto n = static_cast<std::uint64_t>(points);
  if (n > kMaxInputBytes / element) {
    refuse(where, path,
           "declares " + std::to_string(n) + " values of " + size_text(element) +
               ", more than the " + size_text(kMaxInputBytes) + " an input may hold (corrupted)");
  }
  const std::uint64_t declared = n * element;
  const hsize_t stored = H5Dget_storage_size(ds.get());
  const int filters = H5Pget_nfilters(dcpl.get());
  if (filters < 0) refuse(where, path, "cannot be read (corrupted file?)");
  if (layout == H5D_CHUNKED) {
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 1 || rank > H5S_MAX_RANK) refuse(where, path, "corrupted dataspace");
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank)), chunk(dims.size());
    if (H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) != rank ||
        H5Pget_chunk(dcpl.get(), rank, chunk.data()) != rank) {
      refuse(where, path, "corrupted chunk layout");
    }
    std::uint64_t expected = 1;
    for (std::size_t d = 0; d < dims.size(); ++d) {
      if (chunk[d] == 0) refuse(where, path, "corrupted chunk layout (a chunk dimension of 0)");
      expected *= (dims[d] + chunk[d] - 1) / chunk[d];  // at most `n`: no overflow
    }
    hsize_t written = 0;
    if (H5Dget_num_chunks(ds.get(), space.get(), &written) < 0) {
      refuse(where, path, "cannot list its chunks (corrupted file?)");
    }
    // HDF5 reads a chunk never written as its fill value (zeros): no recording or table documents
    // a fill value as data, so such a dataset is not what was measured.
    if (written < expected) {
      refuse(where, path,
             std::to_string(expected - written) + " of its " + std::to_string(expected) +
                 " chunks were never written (HDF5 would read zeros in their place); refused");
    }
  }
  if (filters == 0) {
    if (stored < declared || declared > file_size) {
      refuse(where, path,
             "declares " + size_text(declared) + " of data but stores " + size_text(stored) +
                 " (never written, truncated or corrupted)");
    }
  } else {
    // Deflate expands at most 1032:1 (RFC 1951); the bound is taken for every filter.
    constexpr std::uint64_t kMaxInflateRatio = 1032;
    if (stored == 0 || declared / kMaxInflateRatio > stored ||
        declared / kMaxInflateRatio > file_size) {
      refuse(where, path,
             "declares " + size_text(declared) + " of data but stores only " + size_text(stored) +
                 " compressed (more than compression can give; corrupted)");
    }
  }
}

struct Visit {
  hid_t file;
  const std::string& where;
  std::uint64_t file_size;
  std::exception_ptr error;
};

herr_t visit_link(hid_t group, const char* name, const H5L_info_t* info, void* data) {
  auto& v = *static_cast<Visit*>(data);
  try {
    const std::string path = std::string("/") + name;
    if (info->type == H5L_TYPE_EXTERNAL) {
      refuse(v.where, path,
             "is an external link (to another file); a file must hold its objects itself");
    }
    if (info->type != H5L_TYPE_HARD && info->type != H5L_TYPE_SOFT) {
      refuse(v.where, path, "is a user-defined link; a file must hold its objects itself");
    }
    if (info->type == H5L_TYPE_SOFT) return 0;  // within the file; readers refuse them as needed
    H5O_info_t object;
    if (H5Oget_info_by_name2(group, name, &object, H5O_INFO_BASIC, H5P_DEFAULT) < 0) {
      refuse(v.where, path, "cannot be read (corrupted file?)");
    }
    if (object.type == H5O_TYPE_DATASET) check_dataset(v.file, path, v.where, v.file_size);
  } catch (...) {
    v.error = std::current_exception();
    return -1;
  }
  return 0;
}

}  // namespace

void check_structure(hid_t file, const std::string& where, std::uint64_t file_size) {
  Visit visit{file, where, file_size, nullptr};
  const herr_t status = H5Lvisit(file, H5_INDEX_NAME, H5_ITER_INC, visit_link, &visit);
  if (visit.error) std::rethrow_exception(visit.error);
  if (status < 0) refuse(where, "", "cannot list the file's objects (corrupted file?)");
}

// ---- Hdf5Source ------------------------------------------------------------------------------

Hdf5Source::Hdf5Source(const std::filesystem::path& path, bool signature_at_start)
    : where_(path.string()) {
  check_input_file(path);  // a FIFO, a device, a directory: refused before anything opens it
  // O_NONBLOCK: should the path have become a FIFO since the check, open returns at once.
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd_ < 0) refuse(where_, "", std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size <= 0) {
    ::close(fd_);
    fd_ = -1;
    refuse(where_, "", "is no longer a regular file, or empty (changed while opened)");
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
  if (signature_at_start) {
    static constexpr char kSignature[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
    char head[8] = {};
    if (::pread(fd_, head, sizeof head, 0) != static_cast<ssize_t>(sizeof head) ||
        std::memcmp(head, kSignature, sizeof head) != 0) {
      ::close(fd_);
      fd_ = -1;
      refuse(where_, "", "not an HDF5 file (or truncated)");
    }
  }
}

Hdf5Source::~Hdf5Source() {
  if (fd_ >= 0) ::close(fd_);
}

Hid Hdf5Source::open() const {
  const auto lock = hold_hdf5();
  Hid fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  DriverInfo info;
  info.fd = fd_;
  const hid_t driver = driver_id();
  if (!fapl.valid() || driver < 0 || H5Pset_driver(fapl.get(), driver, &info) < 0 ||
      H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG) < 0) {
    throw_hdf5(where_, "file access properties");
  }
  Hid file(H5Fopen(where_.c_str(), H5F_ACC_RDONLY, fapl.get()), H5Fclose);
  if (!file.valid()) refuse(where_, "", "not an HDF5 file (or truncated)");
  check_structure(file.get(), where_, size_);
  return file;
}

// ---- writing ---------------------------------------------------------------------------------

std::string hdf5_file_bytes(const std::string& where, hid_t fcpl, hid_t fapl,
                            const std::function<void(hid_t file)>& fill) {
  const auto lock = hold_hdf5();
  std::string bytes;
  Hid access(fapl == H5P_DEFAULT ? H5Pcreate(H5P_FILE_ACCESS) : H5Pcopy(fapl), H5Pclose);
  DriverInfo info;
  info.sink = &bytes;
  const hid_t driver = driver_id();
  if (!access.valid() || driver < 0 || H5Pset_driver(access.get(), driver, &info) < 0 ||
      H5Pset_fclose_degree(access.get(), H5F_CLOSE_STRONG) < 0) {
    throw_hdf5(where, "file access properties");
  }
  {
    // Closed before `bytes` goes, also when `fill` throws: in memory, a close cannot fail for
    // want of disk space.
    Hid file(H5Fcreate(where.c_str(), H5F_ACC_TRUNC, fcpl, access.get()), H5Fclose);
    if (!file.valid()) throw_hdf5(where, "cannot create the HDF5 file");
    fill(file.get());
    check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), where, "flush");
    check(file.close(), where, "close");
  }
  return bytes;
}

}  // namespace diag::hdf5_detail
