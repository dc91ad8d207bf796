// Number and list formatting of the text reports (internal to report/src).
#pragma once

#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace report {

// v with `prec` significant digits, as a stream prints it ("1500", "0.25", "1e+05").
inline std::string fmt(double v, int prec = 3) {
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

// "a, b, c"; "none" for an empty list.
inline std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "none" : s;
}

}  // namespace report
