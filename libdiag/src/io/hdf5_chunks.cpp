#include "hdf5_chunks.hpp"

#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/hdf5_inflate.hpp"
#include "hdf5_handle.hpp"

#if GEARDIAG_WITH_LIBDEFLATE
#include <libdeflate.h>
#endif
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace diag {

using hdf5_detail::Hid;

namespace {

std::atomic<bool> direct_reads{true};
std::atomic<bool> force_zlib{false};
std::atomic<bool> reuse_survey_samples{true};

// The filters of a dataset this reader decodes itself: their index in the pipeline (the bit of
// a chunk's filter mask that says the writer skipped it), -1 when absent.
struct Pipeline {
  int shuffle = -1;
  int deflate = -1;
};

// Shuffle and/or deflate, shuffle first, the shuffle for 8-byte elements; nothing else.
bool decodable_pipeline(hid_t dcpl, Pipeline& p) {
  const int n = H5Pget_nfilters(dcpl);
  if (n < 0 || n > 2) return false;
  for (int i = 0; i < n; ++i) {
    unsigned flags = 0, cd[8] = {};
    std::size_t cd_count = 8;
    const H5Z_filter_t id =
        H5Pget_filter2(dcpl, static_cast<unsigned>(i), &flags, &cd_count, cd, 0, nullptr, nullptr);
    if (id == H5Z_FILTER_SHUFFLE && p.shuffle < 0 && p.deflate < 0 && cd_count >= 1 &&
        cd[0] == sizeof(double)) {
      p.shuffle = i;
    } else if (id == H5Z_FILTER_DEFLATE && p.deflate < 0) {
      p.deflate = i;
    } else {
      return false;
    }
  }
  return true;
}

// Inflates the zlib stream in[0, n) into exactly out_size bytes at out; false when the stream is
// damaged, or decodes to another size. Bytes after the stream's end are ignored, as HDF5's own
// filter does.
bool inflate_exact(const unsigned char* in, std::size_t n, unsigned char* out,
                   std::size_t out_size) {
#if GEARDIAG_WITH_LIBDEFLATE
  if (!force_zlib.load(std::memory_order_relaxed)) {
    struct Deleter {
      void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
    };
    thread_local std::unique_ptr<libdeflate_decompressor, Deleter> decompressor(
        libdeflate_alloc_decompressor());
    if (!decompressor) return false;
    std::size_t used = 0, decoded = 0;
    return libdeflate_zlib_decompress_ex(decompressor.get(), in, n, out, out_size, &used,
                                         &decoded) == LIBDEFLATE_SUCCESS &&
           decoded == out_size;
  }
#endif
  if (n > std::numeric_limits<uInt>::max() || out_size > std::numeric_limits<uInt>::max()) {
    return false;
  }
  z_stream z;
  std::memset(&z, 0, sizeof z);
  z.next_in = const_cast<Bytef*>(in);
  z.avail_in = static_cast<uInt>(n);
  z.next_out = out;
  z.avail_out = static_cast<uInt>(out_size);
  if (inflateInit(&z) != Z_OK) return false;
  const int status = inflate(&z, Z_FINISH);
  const bool ok = status == Z_STREAM_END && z.total_out == out_size;
  inflateEnd(&z);
  return ok;
}

// Undoes HDF5's shuffle of 8-byte elements for elements [first, first + count) of a chunk of
// `chunk` elements: byte k of element i is planes[k * chunk + i] (H5Zshuffle.c).
void unshuffle8(const unsigned char* planes, std::size_t chunk, std::size_t first,
                std::size_t count, unsigned char* out) {
  std::size_t i = 0;
#if defined(__SSE2__)
  // 8 elements at a time: an 8 x 8 byte transpose by three rounds of interleaving.
  for (; i + 8 <= count; i += 8) {
    const unsigned char* p = planes + first + i;
    auto load = [&](std::size_t k) {
      return _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p + k * chunk));
    };
    const __m128i t0 = _mm_unpacklo_epi8(load(0), load(1));
    const __m128i t1 = _mm_unpacklo_epi8(load(2), load(3));
    const __m128i t2 = _mm_unpacklo_epi8(load(4), load(5));
    const __m128i t3 = _mm_unpacklo_epi8(load(6), load(7));
    const __m128i u0 = _mm_unpacklo_epi16(t0, t1);
    const __m128i u1 = _mm_unpackhi_epi16(t0, t1);
    const __m128i u2 = _mm_unpacklo_epi16(t2, t3);
    const __m128i u3 = _mm_unpackhi_epi16(t2, t3);
    __m128i* o = reinterpret_cast<__m128i*>(out + 8 * i);
    _mm_storeu_si128(o + 0, _mm_unpacklo_epi32(u0, u2));
    _mm_storeu_si128(o + 1, _mm_unpackhi_epi32(u0, u2));
    _mm_storeu_si128(o + 2, _mm_unpacklo_epi32(u1, u3));
    _mm_storeu_si128(o + 3, _mm_unpackhi_epi32(u1, u3));
  }
#endif
  for (; i < count; ++i) {
    for (std::size_t k = 0; k < 8; ++k) out[8 * i + k] = planes[k * chunk + first + i];
  }
}

}  // namespace

namespace hdf5_detail {

// Makes `buffer` hold at least `bytes` (uninitialised).
void reserve(std::unique_ptr<unsigned char[]>& buffer, std::size_t& capacity, std::size_t bytes) {
  if (capacity >= bytes) return;
  buffer.reset(new unsigned char[bytes]);
  capacity = bytes;
}

bool read_chunks_direct(hid_t ds, const std::string& where, const std::string& what,
                        std::uint64_t offset, std::span<double> out, DecodedChunk& cache) {
  if constexpr (std::endian::native != std::endian::little) return false;
  if (!direct_reads.load(std::memory_order_relaxed) || out.empty()) return false;
  const Hid dcpl(H5Dget_create_plist(ds), H5Pclose);
  const Hid type(H5Dget_type(ds), H5Tclose);
  if (!dcpl.valid() || !type.valid() || H5Pget_layout(dcpl.get()) != H5D_CHUNKED ||
      H5Tequal(type.get(), H5T_IEEE_F64LE) <= 0) {
    return false;
  }
  hsize_t chunk = 0;
  Pipeline pipeline;
  // HDF5 limits a chunk to 4 GiB.
  if (H5Pget_chunk(dcpl.get(), 1, &chunk) != 1 || chunk == 0 ||
      chunk > (std::uint64_t{4} << 30) / sizeof(double) ||
      !decodable_pipeline(dcpl.get(), pipeline) || (pipeline.shuffle < 0 && pipeline.deflate < 0)) {
    return false;  // unfiltered data: HDF5 reads it straight into `out`
  }
  const std::size_t chunk_bytes = static_cast<std::size_t>(chunk) * sizeof(double);
  // A stored chunk is at most HDF5's deflate output bound, ceil(1.001 n) + 12 bytes (a chunk
  // that would be larger is stored raw): anything larger is not a chunk this reader knows.
  const std::size_t max_stored = chunk_bytes + chunk_bytes / 1000 + 64;
  auto* dest = reinterpret_cast<unsigned char*>(out.data());
  const std::uint64_t end = offset + out.size();
  for (std::uint64_t start = offset / chunk * chunk; start < end; start += chunk) {
    if (cache.dataset != what || cache.start != start) {
      cache.dataset.clear();
      const hsize_t at = start;
      hsize_t stored_bytes = 0;
      std::uint32_t mask = 0;
      reserve(cache.stored, cache.stored_capacity, max_stored);
      auto damaged = [&](const std::string& reason) {
        throw InputError(format_error(
            where, what,
            "chunk at sample " + std::to_string(start) + ": " + reason + " (corrupted file)"));
      };
      if (H5Dget_chunk_storage_size(ds, &at, &stored_bytes) < 0 || stored_bytes == 0) {
        damaged("not stored");
      }
      if (stored_bytes > max_stored) {
        damaged("stores " + std::to_string(stored_bytes) + " bytes, more than a chunk of " +
                std::to_string(chunk_bytes) + " bytes is ever stored");
      }
      if (H5Dread_chunk(ds, H5P_DEFAULT, &at, &mask, cache.stored.get()) < 0) {
        damaged("cannot be read");
      }
      if (pipeline.deflate >= 0 && (mask & (1u << pipeline.deflate)) == 0) {
        reserve(cache.bytes, cache.bytes_capacity, chunk_bytes);
        if (!inflate_exact(cache.stored.get(), stored_bytes, cache.bytes.get(), chunk_bytes)) {
          damaged("its deflate stream does not decode to the chunk's " +
                  std::to_string(chunk_bytes) + " bytes");
        }
      } else if (stored_bytes == chunk_bytes) {
        std::swap(cache.stored, cache.bytes);  // stored raw: the chunk itself
        std::swap(cache.stored_capacity, cache.bytes_capacity);
      } else {
        damaged("stored raw in " + std::to_string(stored_bytes) + " bytes, not the chunk's " +
                std::to_string(chunk_bytes));
      }
      cache.shuffled = pipeline.shuffle >= 0 && (mask & (1u << pipeline.shuffle)) == 0;
      cache.dataset = what;
      cache.start = start;
    }
    const std::uint64_t first = std::max<std::uint64_t>(start, offset);
    const std::uint64_t last = std::min<std::uint64_t>(start + chunk, end);
    unsigned char* to = dest + (first - offset) * sizeof(double);
    if (cache.shuffled) {
      unshuffle8(cache.bytes.get(), chunk, first - start, last - first, to);
    } else {
      std::memcpy(to, cache.bytes.get() + (first - start) * sizeof(double),
                  (last - first) * sizeof(double));
    }
  }
  return true;
}

bool reuse_survey() { return reuse_survey_samples.load(std::memory_order_relaxed); }

}  // namespace hdf5_detail

std::string hdf5_inflate_codec() {
#if GEARDIAG_WITH_LIBDEFLATE
  if (!force_zlib.load()) return std::string("libdeflate ") + LIBDEFLATE_VERSION_STRING;
#endif
  return std::string("zlib ") + zlibVersion();
}

bool hdf5_set_read_path(const Hdf5ReadPath& path) {
  direct_reads.store(path.direct);
  force_zlib.store(path.zlib);
  reuse_survey_samples.store(path.reuse_survey);
  return GEARDIAG_WITH_LIBDEFLATE != 0;
}

}  // namespace diag
