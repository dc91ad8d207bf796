// The report's image encoders against their standards: base64 on RFC 4648's test vectors, CRC-32
// on its check value, the PNG decoded by a naive reader written here (chunks, CRCs, the stored
// deflate blocks, Adler-32, the rows), and viridis at its stops and between them.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "report/base64.hpp"
#include "report/colour_map.hpp"
#include "report/png.hpp"

namespace {

TEST(Base64, MatchesTheRfc4648TestVectors) {
  EXPECT_EQ(report::base64(""), "");
  EXPECT_EQ(report::base64("f"), "Zg==");
  EXPECT_EQ(report::base64("fo"), "Zm8=");
  EXPECT_EQ(report::base64("foo"), "Zm9v");
  EXPECT_EQ(report::base64("foob"), "Zm9vYg==");
  EXPECT_EQ(report::base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(report::base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(report::base64(std::string("\xff\x00\xfe", 3)), "/wD+");  // the last two symbols
}

TEST(Crc32, GivesTheStandardCheckValue) {
  EXPECT_EQ(report::crc32("123456789"), 0xcbf43926u);
  EXPECT_EQ(report::crc32(""), 0u);
}

std::uint32_t be32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (std::size_t k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(s[at + k]);
  return v;
}

struct Decoded {
  std::uint32_t width = 0, height = 0;
  std::string palette;     // PLTE's bytes
  std::string raw;         // the inflated IDAT: per row a filter byte and the indices
  std::size_t blocks = 0;  // stored deflate blocks
  bool adler_ok = false;
  std::vector<std::string> types;
};

// A reader for what png_indexed writes: every chunk's CRC checked, IDAT's zlib stream read as
// stored blocks only (BTYPE 00, LEN and its complement), its Adler-32 recomputed.
Decoded decode(const std::string& png) {
  Decoded d;
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n"));
  std::string idat;
  for (std::size_t at = 8; at + 12 <= png.size();) {
    const std::uint32_t len = be32(png, at);
    const std::string type = png.substr(at + 4, 4), data = png.substr(at + 8, len);
    EXPECT_EQ(be32(png, at + 8 + len), report::crc32(type + data)) << type;
    d.types.push_back(type);
    if (type == "IHDR") {
      d.width = be32(data, 0);
      d.height = be32(data, 4);
      EXPECT_EQ(data.substr(8), std::string("\x08\x03\x00\x00\x00", 5));
    }
    if (type == "PLTE") d.palette = data;
    if (type == "IDAT") idat += data;
    at += 12 + len;
  }
  EXPECT_EQ(idat.substr(0, 2), "\x78\x01");  // deflate, 32 K window, check bits
  std::size_t at = 2;
  for (bool last = false; !last;) {
    const auto head = static_cast<unsigned char>(idat[at]);
    last = (head & 1) != 0;
    EXPECT_EQ(head >> 1, 0) << "not a stored block";
    const std::size_t len = static_cast<unsigned char>(idat[at + 1]) |
                            static_cast<std::size_t>(static_cast<unsigned char>(idat[at + 2])) << 8;
    const std::size_t nlen = static_cast<unsigned char>(idat[at + 3]) |
                             static_cast<std::size_t>(static_cast<unsigned char>(idat[at + 4]))
                                 << 8;
    EXPECT_EQ(len ^ 0xffffu, nlen);
    d.raw += idat.substr(at + 5, len);
    at += 5 + len;
    ++d.blocks;
  }
  std::uint32_t a = 1, b = 0;
  for (unsigned char ch : d.raw) {
    a = (a + ch) % 65521;
    b = (b + a) % 65521;
  }
  d.adler_ok = be32(idat, at) == ((b << 16) | a) && at + 4 == idat.size();
  return d;
}

TEST(Png, AnIndexedImageReadsBackPixelForPixel) {
  const std::size_t w = 5, h = 3;
  std::vector<unsigned char> idx(w * h);
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<unsigned char>(7 * i % 4);
  const std::vector<std::array<unsigned char, 3>> palette{
      {0, 0, 0}, {255, 0, 0}, {0, 255, 0}, {0, 0, 255}};
  const Decoded d = decode(report::png_indexed(idx, w, palette));
  EXPECT_EQ(d.types, (std::vector<std::string>{"IHDR", "PLTE", "IDAT", "IEND"}));
  EXPECT_EQ(d.width, w);
  EXPECT_EQ(d.height, h);
  EXPECT_EQ(d.palette, std::string("\0\0\0\xff\0\0\0\xff\0\0\0\xff", 12));
  EXPECT_TRUE(d.adler_ok);
  ASSERT_EQ(d.raw.size(), h * (w + 1));
  for (std::size_t r = 0; r < h; ++r) {
    EXPECT_EQ(d.raw[r * (w + 1)], '\0') << "row " << r << ": filter type 0";
    for (std::size_t c = 0; c < w; ++c) {
      EXPECT_EQ(static_cast<unsigned char>(d.raw[r * (w + 1) + 1 + c]), idx[r * w + c]);
    }
  }
}

TEST(Png, ALargeImageSpansSeveralStoredBlocks) {
  // 300 x 300 indices: 90300 bytes with the filter bytes, more than one block of 65535.
  const std::size_t w = 300;
  std::vector<unsigned char> idx(w * w);
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<unsigned char>(i % 251);
  std::vector<std::array<unsigned char, 3>> palette(256);
  const Decoded d = decode(report::png_indexed(idx, w, palette));
  EXPECT_EQ(d.blocks, 2u);
  EXPECT_TRUE(d.adler_ok);
  ASSERT_EQ(d.raw.size(), w * (w + 1));
  EXPECT_EQ(static_cast<unsigned char>(d.raw[(w - 1) * (w + 1) + w]), idx.back());
}

TEST(Viridis, HitsItsStopsAndInterpolatesBetweenThem) {
  using C = std::array<unsigned char, 3>;
  EXPECT_EQ(report::viridis(0), (C{68, 1, 84}));
  EXPECT_EQ(report::viridis(0.5), (C{33, 145, 140}));
  EXPECT_EQ(report::viridis(1), (C{253, 231, 37}));
  // Halfway between the first two stops: (68+59)/2, (1+82)/2, (84+139)/2, rounded half away.
  EXPECT_EQ(report::viridis(0.125), (C{64, 42, 112}));
  EXPECT_EQ(report::viridis(-3), report::viridis(0));  // clamped
  EXPECT_EQ(report::viridis(7), report::viridis(1));
}

}  // namespace
