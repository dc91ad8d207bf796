#include "diag/io/import.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "csv.hpp"
#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/input_file.hpp"
#include "diag/io/printable.hpp"
#include "diag/util/number_format.hpp"
#include "import_common.hpp"
#include "mat_file.hpp"
#include "sound.hpp"

namespace diag {

namespace {

using namespace import_detail;

// ---- MATLAB .mat ---------------------------------------------------------------------------

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

Recording import_mat(const std::filesystem::path& path, const std::string& where,
                     const ImportOptions& options, std::uint64_t file_size) {
  // Level 7.3 is HDF5: read through the project's one HDF5 open and the crash guard (mat73.cpp).
  std::vector<std::string> notes;
  std::vector<mat::Variable> vars =
      mat::is_mat73(path) ? mat::read_mat73_variables(path, &notes)
                          : mat::read_numeric_variables(path, where, file_size, &notes);
  Recording rec;
  rec.notes = std::move(notes);
  std::vector<std::pair<std::string, double>> rpm_values;
  for (mat::Variable& var : vars) {
    if (var.dims.size() != 2) continue;
    if (var.dims[0] != 1 && var.dims[1] != 1) continue;  // matrices are not channels
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
    for (std::size_t i = 0; i < var.values.size(); ++i) {
      if (!std::isfinite(var.values[i])) {
        throw InputError(format_error(where,
                                      "variable " + var.name + ", sample " + std::to_string(i),
                                      finite_error(var.values[i])));
      }
    }
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

// ---- geardiag HDF5 -------------------------------------------------------------------------

Recording import_hdf5(const std::filesystem::path& path, const std::string& where,
                      const ImportOptions& options) {
  Recording rec = read_recording(path);
  check_option_fs(where, options);
  if (options.fs_hz) {
    for (const auto* group : {&rec.signals, &rec.tachos}) {
      for (const Signal& s : *group) {
        if (!rates_agree(*options.fs_hz, s.fs_hz)) {
          throw InputError(format_error(where, "fs_hz",
                                        "the given " + format_shortest(*options.fs_hz) +
                                            " Hz disagrees with channel " + s.name + "'s " +
                                            format_shortest(s.fs_hz) + " Hz by more than 0.1 %"));
        }
      }
    }
  }
  return rec;
}

}  // namespace

Recording import_recording(const std::filesystem::path& path, const ImportOptions& options) {
  const std::string where = path.string();
  // A FIFO, a device (/dev/zero, also through a link), a directory: refused before any reader
  // opens them, so that none can wait or read without end.
  const std::uint64_t file_size = check_input_file(path);
  const std::string name = lower(path.filename().string());

  Recording rec;
  try {
    if (ends_with(name, ".mat")) {
      rec = import_mat(path, where, options, file_size);
    } else if (is_hdf5_file(path)) {
      rec = import_hdf5(path, where, options);
    } else if (ends_with(name, ".csv") || ends_with(name, ".csv.gz") || ends_with(name, ".tsv") ||
               ends_with(name, ".tsv.gz") || ends_with(name, ".txt") ||
               ends_with(name, ".txt.gz")) {
      rec = import_csv(path, where, options);
    } else if (ends_with(name, ".h5") || ends_with(name, ".hdf5")) {
      throw InputError(format_error(where, "", "not an HDF5 file (or truncated)"));
    } else {
      rec = import_sound(path, where, options, file_size);
    }
  } catch (const std::bad_alloc&) {
    // What a file declares was checked against its bytes; a file that is all data can still be
    // larger than this machine's memory.
    throw InputError(format_error(where, "",
                                  std::to_string(file_size) +
                                      " bytes whose samples do not fit in memory; cut the file "
                                      "or use a machine with more memory"));
  }
  rec.metadata.try_emplace("source", path.filename().string());
  // Names, units and sources come from the file: no escape sequence reaches a terminal.
  make_printable(rec);
  if (!is_hdf5_file(path)) {
    // Measured files say nothing of what their columns are: vibration until a channel map,
    // --tacho or tacho inference (channels.hpp) says otherwise.
    rec.roles_stated = false;
  }
  return rec;
}

}  // namespace diag
