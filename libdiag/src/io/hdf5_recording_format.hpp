// Internal to libdiag: the names the recording format (diag/io/hdf5.hpp) fixes, shared by its
// reader (hdf5_read.cpp) and writer (hdf5_write.cpp).
#pragma once

#include <array>

namespace diag::hdf5_detail {

inline constexpr char kFormatName[] = "geardiag-recording";
// 2: every channel carries role, shaft, mesh, ppr, and the root the recorded speed_rpm. Format-1
// files are still read, their roles inferred (infer_format1_roles).
inline constexpr int kFormatVersion = 2;
// Root attributes owned by the format; Recording::metadata may not use these keys.
inline constexpr std::array<const char*, 6> kReservedAttributes = {
    "format", "format_version", "creator", "git_revision", "input_speed_rpm", "roles_stated"};

}  // namespace diag::hdf5_detail
