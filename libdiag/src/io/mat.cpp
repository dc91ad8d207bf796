// The MAT row of the format table (open_recording.cpp): a .mat file's numeric vectors as channels.
#include "mat.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "diag/error.hpp"
#include "diag/util/number_format.hpp"
#include "import_common.hpp"
#include "mat_file.hpp"

namespace diag {

namespace {

using namespace import_detail;

// Integer classes print exactly; floating ones with the shortest round-trip text.
std::string scalar_text(const mat::Variable& v) {
  if (!v.exact_text.empty()) return v.exact_text;
  if (v.integer_class) return std::to_string(static_cast<long long>(v.values[0]));
  return format_shortest(v.values[0]);
}

// The Case Western Reserve University bearing data's naming (its "Data Files" pages): variable
// X<nnn>_DE_time is the accelerometer at the drive end, X<nnn>_FE_time at the fan end,
// X<nnn>_BA_time on the base. Those channels get that location ("drive_end", "fan_end", "base"),
// so a description whose bearing carries the name finds its sensor (channels.hpp); the unit is
// left unknown (the files do not give it). One note lists them.
void cwru_locations(Recording& rec) {
  static const std::pair<const char*, const char*> kSites[] = {
      {"_DE_time", "drive_end"}, {"_FE_time", "fan_end"}, {"_BA_time", "base"}};
  std::string named;
  for (Signal& s : rec.signals) {
    const std::string& n = s.name;
    std::size_t digits = 0;
    while (1 + digits < n.size() && std::isdigit(static_cast<unsigned char>(n[1 + digits])))
      ++digits;
    if (n.size() != 1 + digits + 8 || n[0] != 'X' || digits == 0 || !s.location.empty()) continue;
    for (const auto& [suffix, site] : kSites) {
      if (n.compare(1 + digits, 8, suffix) != 0) continue;
      s.location = site;
      named += (named.empty() ? "" : ", ") + n + " at " + site;
    }
  }
  if (!named.empty()) {
    rec.notes.push_back("sensor locations from the CWRU bearing data's variable names: " + named);
  }
}

// The recording a file's variables make (mat.hpp); a variable only described (mat73_frames)
// makes a channel without samples.
Recording recording_of(std::vector<mat::Variable>& vars, std::vector<std::string> notes,
                       const std::string& where, const ImportOptions& options) {
  Recording rec;
  rec.notes = std::move(notes);
  std::vector<std::pair<std::string, double>> rpm_values;
  for (mat::Variable& var : vars) {
    if (var.dims.size() != 2) continue;
    if (var.dims[0] != 1 && var.dims[1] != 1) continue;  // matrices are not channels
    if (var.described) {
      Signal s;
      s.name = var.name;
      rec.signals.push_back(std::move(s));
      continue;
    }
    if (var.values.empty()) continue;
    if (var.values.size() == 1) {
      rec.metadata[var.name] = scalar_text(var);
      const std::string lname = lower(var.name);
      // A speed stored with the data (CWRU: X097RPM, X105RPM, ...): the input shaft's speed.
      if (ends_with(lname, "rpm") && var.values[0] > 0 && var.values[0] < 1e6) {
        rpm_values.emplace_back(var.name, var.values[0]);
      }
      continue;
    }
    require_finite(where, "variable " + var.name, 0, var.values);
    Signal s;
    s.name = var.name;
    s.samples = std::move(var.values);
    rec.signals.push_back(std::move(s));
  }
  if (rec.signals.empty()) {
    throw InputError(format_error(where, "", "no numeric vector variables (channels) found"));
  }
  check_option_fs(where, options);
  if (!options.fs_hz) {
    throw InputError(
        format_error(where, "fs_hz", ".mat files do not store the sampling rate: give it (--fs)"));
  }
  for (Signal& s : rec.signals) s.fs_hz = *options.fs_hz;
  cwru_locations(rec);
  if (!rpm_values.empty()) {
    const auto [lo, hi] =
        std::minmax_element(rpm_values.begin(), rpm_values.end(),
                            [](const auto& a, const auto& b) { return a.second < b.second; });
    if (hi->second <= lo->second * 1.001) {
      rec.speed_rpm = rpm_values.front().second;
      rec.notes.push_back("speed " + format_shortest(rec.speed_rpm) + " rpm from variable " +
                          rpm_values.front().first);
    } else {
      rec.notes.push_back("speed variables " + lo->first + " and " + hi->first +
                          " disagree: no recorded speed");
    }
  }
  return rec;
}

}  // namespace

Recording import_mat(const std::filesystem::path& path, const std::string& where,
                     const ImportOptions& options, std::uint64_t file_size) {
  // Level 7.3 is HDF5: read through the project's one HDF5 open and the crash guard (mat73.cpp).
  std::vector<std::string> notes;
  std::vector<mat::Variable> vars =
      mat::is_mat73(path) ? mat::read_mat73_variables(path, &notes)
                          : mat::read_numeric_variables(path, where, file_size, &notes);
  return recording_of(vars, std::move(notes), where, options);
}

std::shared_ptr<const FrameSource> mat_frames(const std::filesystem::path& path,
                                              const std::string& where,
                                              const ImportOptions& options,
                                              std::uint64_t file_size) {
  const mat::Assemble assemble = [&](std::vector<mat::Variable>& vars,
                                     std::vector<std::string>& notes) {
    return recording_of(vars, std::move(notes), where, options);
  };
  if (mat::is_mat73(path)) return mat::mat73_frames(path, assemble);
  return mat::level5_frames(path, where, file_size, assemble);
}

}  // namespace diag
