// Recording times as the tools write and compare them: "YYYY-MM-DDTHH:MM:SS", UTC.
#pragma once

#include <cstdint>
#include <string>

namespace geardiag {

// Seconds since 1970-01-01T00:00:00 of "YYYY-MM-DDTHH:MM:SS" (its first 19 characters), or NaN
// when the text does not start with one.
double epoch_s(const std::string& time);

// The time `seconds` after 1970-01-01T00:00:00 as "YYYY-MM-DDTHH:MM:SS".
std::string iso_time(std::int64_t seconds);

}  // namespace geardiag
