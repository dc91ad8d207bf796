// A PNG encoder for small indexed-colour images (the HTML report's spectrogram): 8-bit palette
// indices, stored (uncompressed) deflate blocks, so no compression library is needed and the
// same pixels always give the same bytes.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace report {

// A PNG (RFC 2083) of 8-bit palette indices `idx`, `width` x idx.size() / width pixels,
// row-major from the top, filter type 0 (none), no interlace; `palette` has at most 256 RGB
// entries. The zlib stream (RFC 1950) holds stored deflate blocks (RFC 1951, BTYPE 00) of at most
// 65535 bytes each, with its Adler-32; every chunk carries its CRC-32.
std::string png_indexed(const std::vector<unsigned char>& idx, std::size_t width,
                        const std::vector<std::array<unsigned char, 3>>& palette);

// CRC-32 of `d` as PNG chunks use it (ISO 3309, polynomial 0xedb88320 reflected): "123456789"
// gives 0xcbf43926.
std::uint32_t crc32(const std::string& d);

}  // namespace report
