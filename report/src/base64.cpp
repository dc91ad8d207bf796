// base64 (base64.hpp).
#include "report/base64.hpp"

#include <cstdint>

namespace report {

std::string base64(const std::string& d) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  for (std::size_t i = 0; i < d.size(); i += 3) {
    std::uint32_t v = static_cast<unsigned char>(d[i]) << 16;
    if (i + 1 < d.size()) v |= static_cast<unsigned char>(d[i + 1]) << 8;
    if (i + 2 < d.size()) v |= static_cast<unsigned char>(d[i + 2]);
    o += k[(v >> 18) & 63];
    o += k[(v >> 12) & 63];
    o += i + 1 < d.size() ? k[(v >> 6) & 63] : '=';
    o += i + 2 < d.size() ? k[v & 63] : '=';
  }
  return o;
}

}  // namespace report
