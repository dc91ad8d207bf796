// The colour map of the report's images: viridis (matplotlib's default map; van der Walt and
// Smith 2015), perceptually uniform and readable in grey and by colour-blind readers.
#pragma once

#include <array>

namespace report {

// The RGB colour of v in [0, 1] (clamped): viridis through five of its colours (0, 1/4, 1/2,
// 3/4, 1), linearly interpolated between them and rounded.
std::array<unsigned char, 3> viridis(double v);

}  // namespace report
