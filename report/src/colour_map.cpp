// viridis (colour_map.hpp).
#include "report/colour_map.hpp"

#include <algorithm>
#include <cmath>

namespace report {

std::array<unsigned char, 3> viridis(double v) {
  static const double kStops[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  const double p = std::clamp(v, 0.0, 1.0) * 4;
  const int i = std::min(3, static_cast<int>(p));
  const double f = p - i;
  std::array<unsigned char, 3> c{};
  for (int k = 0; k < 3; ++k) {
    c[static_cast<std::size_t>(k)] = static_cast<unsigned char>(
        std::lround(kStops[i][k] + f * (kStops[i + 1][k] - kStops[i][k])));
  }
  return c;
}

}  // namespace report
