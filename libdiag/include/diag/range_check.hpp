// A number outside its valid range: error.hpp's fail/require with the value in the message, in
// the one form every option and description check uses:
//   "where: field: <value> (valid <range>)"
// the value printed exactly when it is an integer, else to 6 significant digits (as an ostream
// prints it by default); range says what is allowed, e.g. ">= 3", "1..20", "(0, 300]".
#pragma once

#include <string>
#include <type_traits>

#include "diag/error.hpp"
#include "diag/util/number_format.hpp"

namespace diag {

template <class T>
[[noreturn]] void fail_range(const std::string& where, const std::string& field, T value,
                             const std::string& range) {
  static_assert(std::is_arithmetic_v<T>);
  std::string text;
  if constexpr (std::is_integral_v<T>) {
    text = std::to_string(value);
  } else {
    text = format_significant(static_cast<double>(value), 6);
  }
  fail(where, field, text + " (valid " + range + ")");
}

template <class T>
void require_range(bool ok, const std::string& where, const std::string& field, T value,
                   const std::string& range) {
  if (!ok) fail_range(where, field, value, range);
}

}  // namespace diag
