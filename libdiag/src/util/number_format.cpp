#include "diag/util/number_format.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>

namespace diag {
namespace {

// Longest output: "-1.<17 digits>e+308" for %g, 1 + 309 + 1 + 17 digits for %f (DBL_MAX).
constexpr int kBufferSize = 352;

std::string printed(const char* format, int precision, double value) {
  char buffer[kBufferSize];
  const int n = std::snprintf(buffer, sizeof buffer, format, precision, value);
  return std::string(buffer, static_cast<std::size_t>(std::clamp(n, 0, kBufferSize - 1)));
}

}  // namespace

std::string format_significant(double value, int digits) {
  return printed("%.*g", std::clamp(digits, 0, 17), value);
}

std::string format_fixed(double value, int decimals) {
  return printed("%.*f", std::clamp(decimals, 0, 17), value);
}

std::string format_shortest(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

}  // namespace diag
