#include "mat_file.hpp"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <limits>

#include "diag/error.hpp"
#include "diag/io/input_file.hpp"

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

// Decodes one miMATRIX body. False for a variable an import does not use (skipped).
bool decode_matrix(const Bytes& b, Context& ctx, Variable& out) {
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
  if (cls < kFirstNumericClass || cls > kLastNumericClass) return false;
  if ((word & (kComplexFlag | kLogicalFlag)) != 0) return false;

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
      if (count > b.size) {
        ctx.fail("dimensions declare more elements than the variable's " + std::to_string(b.size) +
                 " bytes hold (corrupted header)");
      }
    }
  }
  if (empty) count = 0;

  const Element real = element_at(b, name.next, ctx, "real part");
  const std::size_t size = type_size(real.type);
  if (size == 0) ctx.fail("real part: data type " + std::to_string(real.type) + " is not numeric");
  if (real.nbytes != count * size) {
    ctx.fail("real part holds " + std::to_string(real.nbytes) + " bytes; the dimensions need " +
             std::to_string(count) + " values of " + std::to_string(size) +
             " bytes = " + std::to_string(count * size));
  }
  out.values.resize(static_cast<std::size_t>(count));
  for (std::size_t i = 0; i < count; ++i)
    out.values[i] = value_of(b, real.data + i * size, real.type);
  out.integer_class = cls >= kFirstIntegerClass;
  if (count == 1 && real.type == kInt64)
    out.exact_text = std::to_string(b.get<std::int64_t>(real.data));
  if (count == 1 && real.type == kUint64) {
    out.exact_text = std::to_string(b.get<std::uint64_t>(real.data));
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

std::vector<Variable> read_level5(const Bytes& file, const std::string& where,
                                  std::vector<std::string>* notes) {
  std::vector<Variable> vars;
  Context ctx{where, 0, {}, notes};
  std::size_t offset = 128;
  while (offset < file.size) {
    ++ctx.index;
    ctx.name.clear();
    if (file.size - offset < 8) {
      const bool zeros = std::all_of(file.data + offset, file.data + file.size,
                                     [](unsigned char c) { return c == 0; });
      if (zeros) break;  // padding at the end of the file
      ctx.fail("truncated (" + std::to_string(file.size - offset) + " bytes after the last one)");
    }
    const std::uint32_t type = file.get<std::uint32_t>(offset);
    const std::size_t nbytes = file.get<std::uint32_t>(offset + 4);
    const std::size_t body = offset + 8;
    if (nbytes > file.size - body) {
      ctx.fail("declares " + std::to_string(nbytes) + " bytes at byte " + std::to_string(offset) +
               ", the file holds only " + std::to_string(file.size - body) +
               " more (truncated or corrupted)");
    }
    Variable v;
    if (type == kMatrix) {
      if (decode_matrix(Bytes{file.data + body, nbytes, file.swap}, ctx, v)) {
        vars.push_back(std::move(v));
      }
    } else if (type == kCompressed) {
      const std::vector<unsigned char> inner =
          inflate_element(file.data + body, nbytes, file.swap, ctx);
      if (decode_matrix(Bytes{inner.data() + 8, inner.size() - 8, file.swap}, ctx, v)) {
        vars.push_back(std::move(v));
      }
    } else if (type == 0 || type > 18) {
      ctx.fail("element type " + std::to_string(type) + " is not a MAT-file type (corrupted)");
    }
    offset = body + nbytes;
  }
  return vars;
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

}  // namespace

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
  // The file in memory once, decoded where it lies.
  const std::string text = read_input_bytes(path, "", file_size);
  const Bytes data{reinterpret_cast<const unsigned char*>(text.data()), text.size(), false};
  if (data.size >= 128) {
    const bool little = data.data[126] == 'I' && data.data[127] == 'M';
    const bool big = data.data[126] == 'M' && data.data[127] == 'I';
    if (little || big) {
      const Bytes file{data.data, data.size,
                       little != (std::endian::native == std::endian::little)};
      const std::uint16_t version = file.get<std::uint16_t>(124);
      if (version != 0x0100) {
        throw InputError(format_error(
            where, "",
            "MAT-file version " + std::to_string(version >> 8) + " is not 5 (level 5) nor 7.3"));
      }
      return read_level5(file, where, notes);
    }
  }
  return read_level4(data, where);
}

}  // namespace diag::mat
