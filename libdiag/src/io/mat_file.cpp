#include "mat_file.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <new>
#include <optional>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/input_file.hpp"
#include "diag/io/printable.hpp"
#include "import_common.hpp"

namespace diag::mat {

namespace {

// Level 5 data types (mat-file-format.pdf, table 1-1).
enum : std::uint32_t {
  kInt8 = 1,
  kUint8 = 2,
  kInt16 = 3,
  kUint16 = 4,
  kInt32 = 5,
  kUint32 = 6,
  kSingle = 7,
  kDouble = 9,
  kInt64 = 12,
  kUint64 = 13,
  kMatrix = 14,
  kCompressed = 15,
};

// Array classes (table 1-3): mxDOUBLE_CLASS = 6 ... mxUINT64_CLASS = 15 are numeric.
constexpr std::uint32_t kFirstNumericClass = 6, kLastNumericClass = 15, kFirstIntegerClass = 8;
constexpr std::uint32_t kComplexFlag = 0x0800, kLogicalFlag = 0x0200;
// Deflate expands at most 1032:1 (RFC 1951: a 258-byte match in a 2-bit code, rounded up).
constexpr std::uint64_t kMaxInflateRatio = 1032;

std::size_t type_size(std::uint32_t type) {
  switch (type) {
    case kInt8:
    case kUint8:
      return 1;
    case kInt16:
    case kUint16:
      return 2;
    case kInt32:
    case kUint32:
    case kSingle:
      return 4;
    case kDouble:
    case kInt64:
    case kUint64:
      return 8;
    default:
      return 0;
  }
}

struct Bytes {
  const unsigned char* data;
  std::size_t size;
  bool swap;  // the file's byte order is not the machine's

  template <typename T>
  T get(std::size_t offset) const {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, data + offset, sizeof(T));
    if (swap) std::reverse(raw, raw + sizeof(T));
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return value;
  }
};

double value_of(const Bytes& b, std::size_t offset, std::uint32_t type) {
  switch (type) {
    case kInt8:
      return b.get<std::int8_t>(offset);
    case kUint8:
      return b.get<std::uint8_t>(offset);
    case kInt16:
      return b.get<std::int16_t>(offset);
    case kUint16:
      return b.get<std::uint16_t>(offset);
    case kInt32:
      return b.get<std::int32_t>(offset);
    case kUint32:
      return b.get<std::uint32_t>(offset);
    case kSingle:
      return b.get<float>(offset);
    case kDouble:
      return b.get<double>(offset);
    case kInt64:
      return static_cast<double>(b.get<std::int64_t>(offset));
    case kUint64:
      return static_cast<double>(b.get<std::uint64_t>(offset));
    default:
      return 0.0;
  }
}

// Names what is being decoded in messages: "variable 3 ('X097_DE_time')".
struct Context {
  const std::string& where;
  std::size_t index = 0;
  std::string name;
  std::vector<std::string>* notes = nullptr;

  [[noreturn]] void fail(const std::string& reason) const {
    std::string field = "variable " + std::to_string(index);
    if (!name.empty()) field += " ('" + name + "')";
    throw InputError(format_error(where, field, reason));
  }
};

struct Element {
  std::uint32_t type = 0;
  std::size_t nbytes = 0;
  std::size_t data = 0;  // offset of the first data byte
  std::size_t next = 0;  // offset of the next element
};

// The element at `offset` of `b`, whose bytes must all lie inside `b`.
Element element_at(const Bytes& b, std::size_t offset, const Context& ctx, const char* what) {
  if (offset > b.size || b.size - offset < 8) {
    ctx.fail(std::string(what) + ": truncated (no room for its tag)");
  }
  Element e;
  const std::uint32_t first = b.get<std::uint32_t>(offset);
  if ((first >> 16) != 0) {  // small data element: 2-byte count, 2-byte type, 4 bytes of data
    e.type = first & 0xFFFF;
    e.nbytes = first >> 16;
    if (e.nbytes > 4)
      ctx.fail(std::string(what) + ": small element of " + std::to_string(e.nbytes) +
               " bytes (at most 4)");
    e.data = offset + 4;
    e.next = offset + 8;
    return e;
  }
  e.type = first;
  e.nbytes = b.get<std::uint32_t>(offset + 4);
  e.data = offset + 8;
  if (e.nbytes > b.size - e.data) {
    ctx.fail(std::string(what) + ": declares " + std::to_string(e.nbytes) + " bytes, only " +
             std::to_string(b.size - e.data) + " remain (truncated or corrupted)");
  }
  // Elements are padded to 8 bytes; the padding of the last one may be cut by its container.
  e.next = std::min(b.size, e.data + ((e.nbytes + 7) / 8) * 8);
  return e;
}

// A numeric matrix's real part as its header declares it: values of `type`, `count` of them,
// from byte `data` of the matrix body, `nbytes` in all.
struct RealPart {
  std::uint32_t type = 0;
  std::uint64_t count = 0;
  std::size_t data = 0;
  std::size_t nbytes = 0;
};

// The header of one miMATRIX body (`declared` bytes, of which `b` holds the first, at least up to
// the real part's tag): the variable's name and dimensions into `out`, and where its real part
// lies. Nothing for a variable an import does not use (skipped).
std::optional<RealPart> matrix_header(const Bytes& b, std::size_t declared, Context& ctx,
                                      Variable& out) {
  const Element flags = element_at(b, 0, ctx, "array flags");
  if (flags.type != kUint32 || flags.nbytes != 8) ctx.fail("array flags: not 8 bytes of uint32");
  const std::uint32_t word = b.get<std::uint32_t>(flags.data);
  const std::uint32_t cls = word & 0xFF;

  const Element dims = element_at(b, flags.next, ctx, "dimensions");
  if (dims.type != kInt32 || dims.nbytes % 4 != 0 || dims.nbytes < 8) {
    ctx.fail("dimensions: not an int32 array of at least 2 values");
  }
  const Element name = element_at(b, dims.next, ctx, "name");
  if (name.type != kInt8 && name.type != kUint8) ctx.fail("name: not a character array");
  out.name.assign(reinterpret_cast<const char*>(b.data + name.data), name.nbytes);
  ctx.name = out.name;
  if (out.name.empty()) ctx.fail("empty variable name");
  if (out.name.find('\0') != std::string::npos) ctx.fail("variable name contains a NUL byte");

  // Variables an import does not use are skipped before their dimensions are weighed: a sparse
  // matrix declares its full size but stores only its non-zeros.
  constexpr std::uint32_t kSparseClass = 5;
  if (cls == kSparseClass && ctx.notes != nullptr) {
    ctx.notes->push_back("variable " + out.name + " skipped: a sparse matrix, not a channel");
  }
  if (cls < kFirstNumericClass || cls > kLastNumericClass) return std::nullopt;
  if ((word & (kComplexFlag | kLogicalFlag)) != 0) return std::nullopt;

  // The element count, refused as soon as it exceeds what the variable's bytes could hold.
  std::uint64_t count = 1;
  bool empty = false;
  for (std::size_t i = 0; i < dims.nbytes / 4; ++i) {
    const std::int32_t d = b.get<std::int32_t>(dims.data + 4 * i);
    if (d < 0) ctx.fail("dimension " + std::to_string(i + 1) + " is negative");
    out.dims.push_back(static_cast<std::size_t>(d));
    if (d == 0) empty = true;
    if (!empty) {
      count *= static_cast<std::uint64_t>(d);
      if (count > declared) {
        ctx.fail("dimensions declare more elements than the variable's " +
                 std::to_string(declared) + " bytes hold (corrupted header)");
      }
    }
  }
  if (empty) count = 0;

  // The real part's tag (its bytes may lie beyond `b`: checked against `declared`).
  const Bytes whole{b.data, declared, b.swap};
  if (name.next > b.size || b.size - name.next < 8) {
    ctx.fail("real part: truncated (no room for its tag)");
  }
  const Element real = element_at(whole, name.next, ctx, "real part");
  const std::size_t size = type_size(real.type);
  if (size == 0) ctx.fail("real part: data type " + std::to_string(real.type) + " is not numeric");
  if (real.nbytes != count * size) {
    ctx.fail("real part holds " + std::to_string(real.nbytes) + " bytes; the dimensions need " +
             std::to_string(count) + " values of " + std::to_string(size) +
             " bytes = " + std::to_string(count * size));
  }
  out.integer_class = cls >= kFirstIntegerClass;
  return RealPart{real.type, count, real.data, real.nbytes};
}

// Decodes one miMATRIX body. False for a variable an import does not use (skipped).
bool decode_matrix(const Bytes& b, Context& ctx, Variable& out) {
  const std::optional<RealPart> real = matrix_header(b, b.size, ctx, out);
  if (!real) return false;
  const std::size_t size = type_size(real->type);
  out.values.resize(static_cast<std::size_t>(real->count));
  for (std::size_t i = 0; i < real->count; ++i) {
    out.values[i] = value_of(b, real->data + i * size, real->type);
  }
  if (real->count == 1 && real->type == kInt64)
    out.exact_text = std::to_string(b.get<std::int64_t>(real->data));
  if (real->count == 1 && real->type == kUint64) {
    out.exact_text = std::to_string(b.get<std::uint64_t>(real->data));
  }
  return true;
}

// Inflates a miCOMPRESSED element: exactly one complete miMATRIX element, its size checked
// against the deflate bound before it is allocated.
std::vector<unsigned char> inflate_element(const unsigned char* data, std::size_t size, bool swap,
                                           const Context& ctx) {
  z_stream z{};
  if (inflateInit(&z) != Z_OK) ctx.fail("cannot start zlib");
  struct End {
    z_stream* z;
    ~End() { inflateEnd(z); }
  } end{&z};
  z.next_in = const_cast<unsigned char*>(data);
  z.avail_in = static_cast<uInt>(std::min<std::size_t>(size, std::numeric_limits<uInt>::max()));
  std::vector<unsigned char> out(8);
  auto run = [&](std::size_t from) {
    z.next_out = out.data() + from;
    z.avail_out = static_cast<uInt>(out.size() - from);
    int rc = Z_OK;
    while (z.avail_out > 0 && rc == Z_OK) {
      rc = inflate(&z, Z_NO_FLUSH);
      if (rc == Z_OK && z.avail_in == 0 && z.avail_out > 0) rc = Z_BUF_ERROR;
    }
    return rc;
  };
  int rc = run(0);
  if (z.avail_out > 0) {
    ctx.fail(std::string("compressed data: ") +
             (rc == Z_BUF_ERROR ? "truncated" : (z.msg != nullptr ? z.msg : "corrupt")));
  }
  const Bytes head{out.data(), 8, swap};
  const std::uint32_t type = head.get<std::uint32_t>(0), nbytes = head.get<std::uint32_t>(4);
  if (type != kMatrix)
    ctx.fail("compressed data does not hold a matrix (type " + std::to_string(type) + ")");
  if (nbytes > size * kMaxInflateRatio + 64) {
    ctx.fail("compressed matrix declares " + std::to_string(nbytes) + " bytes, more than " +
             std::to_string(size) + " compressed bytes can expand to (corrupted)");
  }
  out.resize(8 + static_cast<std::size_t>(nbytes));
  rc = nbytes > 0 ? run(8) : Z_OK;
  if (z.avail_out > 0) {
    ctx.fail(std::string("compressed data: ") +
             (rc == Z_BUF_ERROR ? "truncated" : (z.msg != nullptr ? z.msg : "corrupt")) +
             " after " + std::to_string(z.total_out) + " of " + std::to_string(nbytes + 8) +
             " bytes");
  }
  return out;
}

std::vector<Variable> read_level4(const Bytes& data, const std::string& where) {
  std::vector<Variable> vars;
  Context ctx{where, 0, {}, nullptr};
  std::size_t offset = 0;
  const bool little_host = std::endian::native == std::endian::little;
  while (offset < data.size) {
    ++ctx.index;
    ctx.name.clear();
    if (data.size - offset < 20) ctx.fail("truncated header (level 4)");
    Bytes b{data.data + offset, data.size - offset, false};
    std::int32_t mopt = b.get<std::int32_t>(0);
    if (mopt < 0 || mopt > 4052) {
      b.swap = true;
      mopt = b.get<std::int32_t>(0);
    }
    const int m = mopt / 1000, o = mopt / 100 % 10, p = mopt / 10 % 10, t = mopt % 10;
    const bool file_little = b.swap != little_host;
    if (mopt < 0 || mopt > 4052 || m > 1 || o != 0 || p > 5 || t > 2 || (m == 0) != file_little) {
      ctx.fail("not a MATLAB .mat file (no level 5 header, and no level 4 variable header)");
    }
    const std::int32_t rows = b.get<std::int32_t>(4), cols = b.get<std::int32_t>(8);
    const std::int32_t imag = b.get<std::int32_t>(12), namelen = b.get<std::int32_t>(16);
    if (rows < 0 || cols < 0 || (imag != 0 && imag != 1) || namelen < 1 ||
        static_cast<std::size_t>(namelen) > b.size - 20) {
      ctx.fail("corrupted level-4 header (rows, columns, imaginary flag or name length)");
    }
    std::string name(reinterpret_cast<const char*>(b.data + 20), static_cast<std::size_t>(namelen));
    if (name.back() != '\0') ctx.fail("name is not NUL-terminated (corrupted)");
    name.pop_back();
    ctx.name = name;
    if (name.empty() || name.find('\0') != std::string::npos) ctx.fail("bad variable name");
    static constexpr std::uint32_t kTypes[] = {kDouble, kSingle, kInt32, kInt16, kUint16, kUint8};
    const std::uint32_t type = kTypes[p];
    const std::size_t size = type_size(type);
    const std::size_t start = 20 + static_cast<std::size_t>(namelen);
    const std::uint64_t count = static_cast<std::uint64_t>(rows) * static_cast<std::uint64_t>(cols);
    const std::uint64_t parts = imag != 0 ? 2 : 1;
    // Compared by division first: rows x columns x 8 x 2 can pass 2^64 and wrap to a small size.
    const std::uint64_t room = b.size - start;
    if (count > room / size / parts) {
      ctx.fail("dimensions " + std::to_string(rows) + " x " + std::to_string(cols) + " need " +
               std::to_string(count) + " values, more than the " + std::to_string(room) +
               " bytes left hold (truncated or corrupted)");
    }
    const std::uint64_t need = count * size * parts;
    if (need > b.size - start) {
      ctx.fail("needs " + std::to_string(need) + " bytes of data, the file holds " +
               std::to_string(b.size - start) + " (truncated or corrupted)");
    }
    if (t == 0 && imag == 0) {
      Variable v;
      v.name = name;
      v.dims = {static_cast<std::size_t>(rows), static_cast<std::size_t>(cols)};
      v.values.resize(static_cast<std::size_t>(count));
      for (std::size_t i = 0; i < count; ++i) v.values[i] = value_of(b, start + i * size, type);
      vars.push_back(std::move(v));
    }
    offset += start + static_cast<std::size_t>(need);
  }
  return vars;
}

// ---- level 5, frame by frame -----------------------------------------------------------------

// Elements up to this size are read and decoded whole (scalars, short vectors); larger vectors
// are described from their first kHeadBytes and read frame by frame.
constexpr std::size_t kWholeElement = std::size_t{1} << 16;
constexpr std::size_t kHeadBytes = std::size_t{1} << 12;
constexpr std::size_t kReadBlock = std::size_t{1} << 16;

// The file opened once, read at offsets.
class File {
 public:
  explicit File(const std::filesystem::path& path) : where_(path.string()) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0)
      throw InputError(
          format_error(where_, "", std::string("cannot open: ") + std::strerror(errno)));
  }
  ~File() { ::close(fd_); }
  File(const File&) = delete;
  File& operator=(const File&) = delete;
  // Up to n bytes at `offset` (fewer only at the end of the file).
  std::size_t read(std::uint64_t offset, unsigned char* out, std::size_t n) const {
    std::size_t done = 0;
    while (done < n) {
      const ssize_t r = ::pread(fd_, out + done, n - done, static_cast<off_t>(offset + done));
      if (r < 0 && errno == EINTR) continue;
      if (r < 0)
        throw InputError(
            format_error(where_, "", std::string("cannot read: ") + std::strerror(errno)));
      if (r == 0) break;
      done += static_cast<std::size_t>(r);
    }
    return done;
  }
  std::vector<unsigned char> bytes(std::uint64_t offset, std::size_t n, const Context& ctx) const {
    std::vector<unsigned char> out(n);
    if (read(offset, out.data(), n) != n) ctx.fail("truncated (the file changed while read?)");
    return out;
  }

 private:
  std::string where_;
  int fd_ = -1;
};

// A miCOMPRESSED element's inflated stream, read forward from where the last read ended (a read
// before that starts the stream again): frames read in order inflate the element once.
class Inflater {
 public:
  Inflater(const File& file, std::uint64_t begin, std::uint64_t bytes)
      : file_(&file), begin_(begin), bytes_(bytes), in_(kReadBlock) {
    start();
  }
  ~Inflater() { inflateEnd(&z_); }
  Inflater(const Inflater&) = delete;
  Inflater& operator=(const Inflater&) = delete;

  // The stream's bytes [from, from + n) into `out`; fewer at the stream's end. Throws InputError
  // (ctx) on corrupt data.
  std::size_t read(std::uint64_t from, unsigned char* out, std::size_t n, const Context& ctx) {
    if (from < produced_) {
      inflateEnd(&z_);
      start();
    }
    std::vector<unsigned char> skip;
    while (produced_ < from) {
      skip.resize(static_cast<std::size_t>(std::min<std::uint64_t>(kReadBlock, from - produced_)));
      if (pump(skip.data(), skip.size(), ctx) < skip.size()) return 0;
    }
    return pump(out, n, ctx);
  }

 private:
  void start() {
    z_ = z_stream{};
    if (inflateInit(&z_) != Z_OK) throw std::bad_alloc();
    consumed_ = produced_ = 0;
    ended_ = false;
  }
  std::size_t pump(unsigned char* out, std::size_t n, const Context& ctx) {
    std::size_t done = 0;
    while (done < n && !ended_) {
      if (z_.avail_in == 0) {
        const std::size_t want =
            static_cast<std::size_t>(std::min<std::uint64_t>(in_.size(), bytes_ - consumed_));
        if (want == 0) ctx.fail("compressed data: truncated");
        if (file_->read(begin_ + consumed_, in_.data(), want) != want) {
          ctx.fail("compressed data: truncated (the file changed while read?)");
        }
        consumed_ += want;
        z_.next_in = in_.data();
        z_.avail_in = static_cast<uInt>(want);
      }
      z_.next_out = out + done;
      z_.avail_out = static_cast<uInt>(std::min<std::size_t>(n - done, kReadBlock));
      const uInt before = z_.avail_out;
      const int rc = inflate(&z_, Z_NO_FLUSH);
      if (rc != Z_OK && rc != Z_STREAM_END && rc != Z_BUF_ERROR) {
        ctx.fail(std::string("compressed data: ") + (z_.msg != nullptr ? z_.msg : "corrupt"));
      }
      done += before - z_.avail_out;
      ended_ = rc == Z_STREAM_END;
    }
    produced_ += done;
    return done;
  }

  const File* file_;
  std::uint64_t begin_, bytes_;
  std::vector<unsigned char> in_;
  z_stream z_{};
  std::uint64_t consumed_ = 0, produced_ = 0;
  bool ended_ = false;
};

// Where a vector variable's values lie: in the file (a miMATRIX element) or in the inflated
// stream of a miCOMPRESSED one.
struct Place {
  std::string variable;
  RealPart real;           // its offsets relative to `data`'s origin below
  std::uint64_t data = 0;  // the first value: a file offset, or an offset in the inflated stream
  bool compressed = false;
  std::uint64_t element = 0, element_bytes = 0;  // the compressed element's body in the file
};

bool is_vector(const std::vector<std::size_t>& dims) {
  return dims.size() == 2 && (dims[0] == 1 || dims[1] == 1);
}

// A large element's header: where its values lie when it is a numeric vector (else nothing).
std::optional<Place> describe(const File& file, std::uint32_t type, std::uint64_t body,
                              std::uint64_t nbytes, bool swap, Context& ctx, Variable& v) {
  Place p;
  std::vector<unsigned char> head;
  std::uint64_t declared = nbytes;
  std::size_t skip = 0;  // bytes before the matrix body in `head`
  if (type == kMatrix) {
    head = file.bytes(body, static_cast<std::size_t>(std::min<std::uint64_t>(nbytes, kHeadBytes)),
                      ctx);
  } else {
    Inflater z(file, body, nbytes);
    head.resize(kHeadBytes + 8);
    head.resize(z.read(0, head.data(), head.size(), ctx));
    if (head.size() < 8) ctx.fail("compressed data: truncated");
    const Bytes tag{head.data(), 8, swap};
    if (tag.get<std::uint32_t>(0) != kMatrix) {
      ctx.fail("compressed data does not hold a matrix (type " +
               std::to_string(tag.get<std::uint32_t>(0)) + ")");
    }
    declared = tag.get<std::uint32_t>(4);
    if (declared > nbytes * kMaxInflateRatio + 64) {
      ctx.fail("compressed matrix declares " + std::to_string(declared) + " bytes, more than " +
               std::to_string(nbytes) + " compressed bytes can expand to (corrupted)");
    }
    skip = 8;
    p.compressed = true;
    p.element = body;
    p.element_bytes = nbytes;
  }
  const std::optional<RealPart> real =
      matrix_header(Bytes{head.data() + skip, head.size() - skip, swap},
                    static_cast<std::size_t>(declared), ctx, v);
  if (!real || !is_vector(v.dims) || real->count < 2) return std::nullopt;
  p.variable = v.name;
  p.real = *real;
  p.data = (p.compressed ? skip : body) + real->data;
  return p;
}

// A level 5 file's variables, element by element from the file (never the whole file in
// memory): an element of at most `whole` bytes is read and decoded whole; a larger numeric
// vector only described, its place added to `places` (with `places` null, every element is
// decoded whole).
std::vector<Variable> survey_level5(const File& file, const std::string& where,
                                    std::uint64_t file_size, bool swap, std::uint64_t whole,
                                    std::vector<std::string>* notes, std::vector<Place>* places) {
  std::vector<Variable> vars;
  Context ctx{where, 0, {}, notes};
  std::uint64_t offset = 128;
  while (offset < file_size) {
    ++ctx.index;
    ctx.name.clear();
    if (file_size - offset < 8) {
      const auto rest = file.bytes(offset, static_cast<std::size_t>(file_size - offset), ctx);
      if (std::all_of(rest.begin(), rest.end(), [](unsigned char c) { return c == 0; })) break;
      ctx.fail("truncated (" + std::to_string(file_size - offset) + " bytes after the last one)");
    }
    const auto tag = file.bytes(offset, 8, ctx);
    const Bytes t{tag.data(), 8, swap};
    const std::uint32_t type = t.get<std::uint32_t>(0);
    const std::uint64_t nbytes = t.get<std::uint32_t>(4);
    const std::uint64_t body = offset + 8;
    if (nbytes > file_size - body) {
      ctx.fail("declares " + std::to_string(nbytes) + " bytes at byte " + std::to_string(offset) +
               ", the file holds only " + std::to_string(file_size - body) +
               " more (truncated or corrupted)");
    }
    if (type == kMatrix || type == kCompressed) {
      Variable v;
      if (places == nullptr || nbytes <= whole) {
        const auto b = file.bytes(body, static_cast<std::size_t>(nbytes), ctx);
        bool used = false;
        if (type == kMatrix) {
          used = decode_matrix(Bytes{b.data(), b.size(), swap}, ctx, v);
        } else {
          const auto inner = inflate_element(b.data(), b.size(), swap, ctx);
          used = decode_matrix(Bytes{inner.data() + 8, inner.size() - 8, swap}, ctx, v);
        }
        if (used) vars.push_back(std::move(v));
      } else if (auto place = describe(file, type, body, nbytes, swap, ctx, v)) {
        places->push_back(*place);
        v.described = true;
        vars.push_back(std::move(v));
      }
    } else if (type == 0 || type > 18) {
      ctx.fail("element type " + std::to_string(type) + " is not a MAT-file type (corrupted)");
    }
    offset = body + nbytes;
  }
  return vars;
}

// From a file's first 128 bytes: whether its level 5 data are in the other byte order than this
// machine's; nothing when it has no level 5 header (level 4). Throws InputError for another
// version.
std::optional<bool> level5_swap(const unsigned char (&head)[128], const std::string& where) {
  const bool little = head[126] == 'I' && head[127] == 'M';
  const bool big = head[126] == 'M' && head[127] == 'I';
  if (!little && !big) return std::nullopt;
  const bool swap = little != (std::endian::native == std::endian::little);
  const std::uint16_t version = Bytes{head, sizeof head, swap}.get<std::uint16_t>(124);
  if (version != 0x0100) {
    throw InputError(format_error(
        where, "",
        "MAT-file version " + std::to_string(version >> 8) + " is not 5 (level 5) nor 7.3"));
  }
  return swap;
}

// A level 5 file's vectors read frame by frame (level5_frames): the large ones at their places,
// the short ones (decoded whole by the survey) from memory.
class Level5Frames final : public VariableFrames {
 public:
  Level5Frames(const std::filesystem::path& path, const std::string& where, std::uint64_t file_size,
               bool swap, const Assemble& assemble)
      : file_(path), swap_(swap) {
    std::vector<std::string> notes;
    std::vector<Place> places;
    std::vector<Variable> vars =
        survey_level5(file_, where, file_size, swap, kWholeElement, &notes, &places);
    Recording rec = assemble(vars, notes);
    for (const Signal& sig : rec.signals) {
      const auto it = std::find_if(places.begin(), places.end(),
                                   [&](const Place& p) { return p.variable == sig.name; });
      sources_.push_back(it == places.end() ? Source{std::nullopt, sig.samples} : Source{*it, {}});
    }
    inflaters_.resize(sources_.size());
    set_recording(std::move(rec), path, where, [&](std::size_t i, const Signal&) {
      return sources_[i].place ? sources_[i].place->real.count : sources_[i].values.size();
    });
  }

 private:
  struct Source {
    std::optional<Place> place;  // none: decoded whole, `values`
    std::vector<double> values;
  };

  void read_span(std::size_t i, std::uint64_t first, std::span<double> out) const override {
    const Source& s = sources_[i];
    if (!s.place) {
      std::copy_n(s.values.begin() + static_cast<std::ptrdiff_t>(first), out.size(), out.begin());
      return;
    }
    const Place& p = *s.place;
    const std::size_t size = type_size(p.real.type);
    std::vector<unsigned char> raw(out.size() * size);
    const Context ctx{where(), 0, p.variable, nullptr};
    const std::uint64_t at = p.data + first * size;
    if (p.compressed) {
      auto& z = inflaters_[i];
      if (!z) z = std::make_unique<Inflater>(file_, p.element, p.element_bytes);
      if (z->read(at, raw.data(), raw.size(), ctx) != raw.size()) {
        ctx.fail("compressed data: ends before its values do (truncated)");
      }
    } else if (file_.read(at, raw.data(), raw.size()) != raw.size()) {
      ctx.fail("truncated (the file changed while read?)");
    }
    const Bytes b{raw.data(), raw.size(), swap_};
    for (std::size_t j = 0; j < out.size(); ++j) out[j] = value_of(b, j * size, p.real.type);
  }

  File file_;
  bool swap_;
  std::vector<Source> sources_;
  mutable std::vector<std::unique_ptr<Inflater>> inflaters_;  // frames are read one at a time
};

}  // namespace

void VariableFrames::set_recording(
    Recording rec, const std::filesystem::path& path, const std::string& where,
    const std::function<std::uint64_t(std::size_t, const Signal&)>& length) {
  where_ = where;
  for (std::size_t i = 0; i < rec.signals.size(); ++i) {
    Signal& s = rec.signals[i];
    channels_.push_back({s.name, length(i, s), s.fs_hz});
    s.samples.clear();
  }
  // As every measured format's recording: named after its file, printable, roles unstated.
  rec.metadata.try_emplace("source", path.filename().string());
  make_printable(rec);
  rec.roles_stated = false;
  recording_ = std::move(rec);
}

std::vector<ChannelExtent> VariableFrames::extents() const {
  std::vector<ChannelExtent> out;
  for (const Channel& c : channels_) out.push_back({c.length, c.fs_hz});
  return out;
}

Recording VariableFrames::frame(double t0_s, double t1_s) const {
  Recording rec = recording_;
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    const Channel& c = channels_[i];
    const std::uint64_t first = samples_within(c.length, c.fs_hz, t0_s);
    const std::uint64_t end = std::max(first, samples_within(c.length, c.fs_hz, t1_s));
    std::vector<double>& x = rec.signals[i].samples;
    x.resize(static_cast<std::size_t>(end - first));
    if (!x.empty()) read_span(i, first, x);
    import_detail::require_finite(where_, "variable " + c.variable, first, x);
  }
  return rec;
}

std::shared_ptr<const FrameSource> level5_frames(const std::filesystem::path& path,
                                                 const std::string& where, std::uint64_t file_size,
                                                 const Assemble& assemble) {
  unsigned char head[128] = {};
  {
    const File file(path);
    if (file_size < 128 || file.read(0, head, sizeof head) != sizeof head) return nullptr;
  }
  const std::optional<bool> swap = level5_swap(head, where);
  if (!swap) return nullptr;  // level 4
  return std::make_shared<const Level5Frames>(path, where, file_size, *swap, assemble);
}

bool is_mat73(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char head[128] = {};
  if (!in.read(head, sizeof head)) return false;
  const bool little = head[126] == 'I' && head[127] == 'M';
  const bool big = head[126] == 'M' && head[127] == 'I';
  const auto version = static_cast<unsigned>(static_cast<unsigned char>(head[little ? 125 : 124]));
  return (little || big) && version == 2;
}

std::vector<Variable> read_numeric_variables(const std::filesystem::path& path,
                                             const std::string& where, std::uint64_t file_size,
                                             std::vector<std::string>* notes) {
  {
    // Level 5: element by element (each element's bytes in memory once, decoded where they lie).
    unsigned char head[128] = {};
    const File file(path);
    if (file_size >= 128 && file.read(0, head, sizeof head) == sizeof head) {
      if (const std::optional<bool> swap = level5_swap(head, where)) {
        return survey_level5(file, where, file_size, *swap, file_size, notes, nullptr);
      }
    }
  }
  // Level 4: the file in memory once, decoded where it lies.
  const std::string text = read_input_bytes(path, "", file_size);
  return read_level4(Bytes{reinterpret_cast<const unsigned char*>(text.data()), text.size(), false},
                     where);
}

}  // namespace diag::mat
