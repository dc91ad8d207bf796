// Numbers (and lists) as text, one function per format, so that the name says what is printed:
//   format_significant(v, d)  d significant digits, trailing zeros dropped, exponent when the
//                             number is very large or small (printf's %.<d>g; what an ostream
//                             prints after precision(d), its default being 6);
//   format_fixed(v, d)        d digits after the decimal point (printf's %.<d>f;
//                             std::to_string(double) is format_fixed(v, 6));
//   format_shortest(v)        the shortest text that reads back to the same double
//                             (std::to_chars, round trip exact).
//   format_list(items)        "a, b, c"; "none" for an empty list.
// Non-finite values print as "inf", "-inf", "nan" (or "-nan") in every format. The decimal point
// is '.': printf's in the "C" locale, which geardiag never changes.
#pragma once

#include <string>
#include <vector>

namespace diag {

// digits: 1..17 (0 is taken as 1, as printf does); e.g. format_significant(3.14159, 4) = "3.142",
// format_significant(1234567, 6) = "1.23457e+06".
std::string format_significant(double value, int digits);

// decimals: 0..17; e.g. format_fixed(2.5, 1) = "2.5", format_fixed(2.0, 3) = "2.000".
std::string format_fixed(double value, int decimals);

// e.g. format_shortest(0.1) = "0.1", format_shortest(1e21) = "1e+21".
std::string format_shortest(double value);

inline std::string format_list(const std::vector<std::string>& items) {
  std::string s;
  for (const auto& x : items) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "none" : s;
}

}  // namespace diag
