// png_indexed (png.hpp).
#include "report/png.hpp"

#include <algorithm>

namespace report {

namespace {

void put_be32(std::string& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out += static_cast<char>((v >> s) & 0xffu);
}

}  // namespace

std::uint32_t crc32(const std::string& d) {
  std::uint32_t c = 0xffffffffu;
  for (unsigned char ch : d) {
    c ^= ch;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

std::string png_indexed(const std::vector<unsigned char>& idx, std::size_t width,
                        const std::vector<std::array<unsigned char, 3>>& palette) {
  const std::size_t rows = idx.size() / width;
  std::string raw;
  for (std::size_t r = 0; r < rows; ++r) {
    raw += '\0';  // filter type 0 (none)
    raw.append(reinterpret_cast<const char*>(idx.data() + r * width), width);
  }
  std::string z = "\x78\x01";
  for (std::size_t at = 0; at < raw.size() || at == 0; at += 65535) {
    const std::size_t len = std::min<std::size_t>(65535, raw.size() - at);
    z += static_cast<char>(at + len >= raw.size() ? 1 : 0);  // BFINAL on the last, BTYPE 00
    z += static_cast<char>(len & 0xff);
    z += static_cast<char>(len >> 8);
    z += static_cast<char>(~len & 0xff);
    z += static_cast<char>((~len >> 8) & 0xff);
    z.append(raw, at, len);
  }
  // Adler-32 (RFC 1950) of the uncompressed data.
  std::uint32_t a = 1, b = 0;
  for (unsigned char ch : raw) {
    a = (a + ch) % 65521;
    b = (b + a) % 65521;
  }
  put_be32(z, (b << 16) | a);
  std::string png = "\x89PNG\r\n\x1a\n";
  const auto chunk = [&png](const std::string& type, const std::string& data) {
    put_be32(png, static_cast<std::uint32_t>(data.size()));
    png += type + data;
    put_be32(png, crc32(type + data));
  };
  std::string ihdr;
  put_be32(ihdr, static_cast<std::uint32_t>(width));
  put_be32(ihdr, static_cast<std::uint32_t>(rows));
  ihdr += std::string("\x08\x03\x00\x00\x00", 5);  // 8 bits, palette, deflate, no filter/interlace
  chunk("IHDR", ihdr);
  std::string plte;
  for (const auto& c : palette) plte.append(reinterpret_cast<const char*>(c.data()), 3);
  chunk("PLTE", plte);
  chunk("IDAT", z);
  chunk("IEND", "");
  return png;
}

}  // namespace report
