// What the format readers (open_recording.cpp, mat.cpp, csv.cpp, sound.cpp) share: the rate
// tolerance and small text helpers.
#pragma once

#include <cctype>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "diag/error.hpp"
#include "diag/io/import.hpp"
#include "diag/util/number_format.hpp"

namespace diag::import_detail {

// Sampling rates that disagree by more than this fraction are refused (import.hpp); time stamps
// must be uniformly spaced within the same fraction of the sample period.
inline constexpr double kRateRelTol = 1e-3;

inline std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

inline bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

inline std::string finite_error(double value) {
  return std::string(std::isnan(value) ? "NaN" : "infinite") + " value; samples must be finite";
}

// Refuses the first NaN or infinite value of `samples`, samples `first` ... of `what` (e.g.
// "variable x", "channel ch0"), naming it: "<where>: <what>, sample <n>: NaN value; ...".
inline void require_finite(const std::string& where, const std::string& what, std::uint64_t first,
                           std::span<const double> samples) {
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(samples[i])) {
      throw InputError(format_error(where, what + ", sample " + std::to_string(first + i),
                                    finite_error(samples[i])));
    }
  }
}

inline void check_option_fs(const std::string& where, const ImportOptions& options) {
  if (options.fs_hz && (!(*options.fs_hz > 0.0) || !std::isfinite(*options.fs_hz))) {
    throw InputError(format_error(
        where, "fs_hz", format_shortest(*options.fs_hz) + " Hz is not a finite rate > 0"));
  }
}

inline std::string count_text(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

inline bool rates_agree(double a, double b) { return std::abs(a - b) <= kRateRelTol * std::abs(b); }

}  // namespace diag::import_detail
