// geardiag info FILE [--fs HZ] [--json]: channels, metadata, gearbox summary and ground truth of
// a recording (HDF5, or CSV / WAV / MAT read as `geardiag import` would).
// geardiag info --gearbox GEARBOX.json [--json]: the derived quantities of a gearbox description.
#include <algorithm>
#include <boost/program_options.hpp>
#include <cstdio>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cli_options.hpp"
#include "commands.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/import.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/io/truth.hpp"
#include "facegear_cmd.hpp"
#include "output.hpp"

namespace geardiag {

namespace po = boost::program_options;

namespace {

// What `info` reports, gathered without loading samples when the file is an HDF5 recording.
struct Description {
  std::string file;
  std::map<std::string, std::string> format;  // format, format_version, creator, git_revision
  std::vector<diag::ChannelInfo> channels;
  std::map<std::string, std::string> metadata;
  std::string gearbox_json;
  std::string truth_json;
};

Description describe(const std::string& file, const diag::ImportOptions& options) {
  Description d;
  d.file = file;
  if (diag::is_hdf5_file(file) && !options.fs_hz &&
      diag::RecordingReader(file).format_version() >= 2) {
    const diag::RecordingReader reader(file);
    d.format = reader.format_attributes();
    d.channels = reader.channels();
    d.metadata = reader.metadata();
    d.gearbox_json = reader.gearbox_json();
    d.truth_json = reader.truth_json();
    return d;
  }
  const diag::Recording rec = diag::import_recording(file, options);
  for (const auto* group : {&rec.signals, &rec.tachos}) {
    for (const diag::Signal& s : *group) {
      diag::ChannelInfo c;
      c.identity() = s.identity();
      c.group = group == &rec.signals ? "signals" : "tacho";
      c.length = s.samples.size();
      d.channels.push_back(std::move(c));
    }
  }
  d.metadata = rec.metadata;
  for (const std::string& n : rec.notes)
    d.metadata["note"] += (d.metadata["note"].empty() ? "" : "; ") + n;
  d.gearbox_json = rec.gearbox_json;
  d.truth_json = rec.truth_json;
  return d;
}

double duration_s(const diag::ChannelInfo& c) {
  return c.fs_hz > 0 ? static_cast<double>(c.length) / c.fs_hz : 0.0;
}

std::optional<diag::Gearbox> gearbox_of(const Description& d) {
  if (d.gearbox_json.empty()) return std::nullopt;
  // A face-gear pair recording: its description is shown through the truth (model, DLF, ...).
  if (is_face_gear_text(d.gearbox_json, d.file + ": /gearbox")) return std::nullopt;
  return diag::parse_gearbox_text(d.gearbox_json, d.file + ": /gearbox");
}

nlohmann::json truth_of(const Description& d) {
  if (d.truth_json.empty()) return nullptr;
  // Shown as text when it is not JSON within the limits (depth, size): never parsed unbounded.
  try {
    // Typed and checked (diag/io/truth.hpp), written back in its one layout; a truth that is JSON
    // but not a simulator's (another tool's, hand-written) is shown as it is.
    try {
      return diag::parse_truth(d.truth_json, d.file)->to_json();
    } catch (const diag::InputError&) {
      return diag::parse_json_text(d.truth_json, d.file + ": /truth");
    }
  } catch (const diag::InputError&) {
    return nlohmann::json(d.truth_json);
  }
}

void print_text(const Description& d) {
  std::cout << d.file << "\n";
  for (const auto& [key, value] : d.format) std::cout << "  " << key << ": " << value << "\n";

  // Column widths from the content so that the table lines up.
  std::vector<std::vector<std::string>> rows = {{"name", "group", "samples", "fs_hz", "duration_s",
                                                 "unit", "role", "direction", "location", "shaft",
                                                 "mesh"}};
  for (const auto& c : d.channels) {
    char fs[32], duration[32];
    std::snprintf(fs, sizeof fs, "%.6g", c.fs_hz);
    std::snprintf(duration, sizeof duration, "%.3f", duration_s(c));
    const std::string direction(diag::to_string(c.direction));
    rows.push_back({c.name, c.group, std::to_string(c.length), fs, duration,
                    c.unit.empty() ? "-" : c.unit,
                    std::string(diag::to_string(c.role)) +
                        (c.role == diag::Role::kTacho ? "/" + std::to_string(c.ppr) : ""),
                    direction.empty() ? "-" : direction, c.location.empty() ? "-" : c.location,
                    c.shaft.empty() ? "-" : c.shaft, c.mesh.empty() ? "-" : c.mesh});
  }
  std::vector<std::size_t> width(rows[0].size(), 0);
  for (const auto& row : rows) {
    for (std::size_t i = 0; i < row.size(); ++i) width[i] = std::max(width[i], row[i].size());
  }
  std::cout << "channels (" << d.channels.size() << "):\n";
  for (const auto& row : rows) {
    std::cout << " ";
    for (std::size_t i = 0; i < row.size(); ++i) {
      // Numbers right-aligned, text left-aligned.
      const bool numeric = i >= 2 && i <= 4;
      const std::string pad(width[i] - row[i].size(), ' ');
      std::cout << "  " << (numeric ? pad + row[i] : row[i] + (i + 1 < row.size() ? pad : ""));
    }
    std::cout << "\n";
  }
  if (!d.metadata.empty()) {
    std::cout << "metadata:\n";
    for (const auto& [key, value] : d.metadata) std::cout << "  " << key << ": " << value << "\n";
  }
  if (auto gb = gearbox_of(d)) std::cout << "gearbox:\n" << diag::format_summary(*gb) << "\n";
  if (!d.truth_json.empty()) std::cout << "truth:\n" << truth_of(d).dump(2) << "\n";
}

nlohmann::json to_json(const Description& d) {
  nlohmann::json j;
  j["file"] = d.file;
  j["format"] = d.format;
  j["channels"] = nlohmann::json::array();
  for (const auto& c : d.channels) {
    j["channels"].push_back({{"name", c.name},
                             {"group", c.group},
                             {"samples", c.length},
                             {"fs_hz", c.fs_hz},
                             {"duration_s", duration_s(c)},
                             {"unit", c.unit},
                             {"direction", std::string(diag::to_string(c.direction))},
                             {"location", c.location},
                             {"role", std::string(diag::to_string(c.role))},
                             {"shaft", c.shaft},
                             {"mesh", c.mesh},
                             {"ppr", c.ppr}});
  }
  j["metadata"] = d.metadata;
  if (auto gb = gearbox_of(d)) j["gearbox"] = diag::summary_json(*gb);
  if (!d.truth_json.empty()) j["truth"] = truth_of(d);
  return j;
}

}  // namespace

int cmd_info(int argc, char** argv) {
  std::string file, gearbox;
  po::options_description visible(
      "usage: geardiag info FILE [--fs HZ] [--json]\n"
      "       geardiag info --gearbox GEARBOX.json [--json]\n\n"
      "Describes a recording (channels, metadata, gearbox summary, ground truth) without loading\n"
      "its samples, or a gearbox description (shaft speeds, mesh frequencies, periods).\n"
      "FILE may be a geardiag .h5 recording or anything `geardiag import` reads.\n\noptions");
  visible.add_options()             //
      ("help,h", "show this help")  //
      ("gearbox", po::value<std::string>(&gearbox)->value_name("FILE"),
       "describe a gearbox description (JSON) instead of a recording")  //
      ("fs", po::value<double>()->value_name("HZ"),
       "sampling rate [Hz], > 0, for files that do not store it (.mat, CSV without a time "
       "column)")  //
      ("json", "print JSON instead of text (keys carry units)");
  po::options_description hidden;
  hidden.add_options()("file", po::value<std::string>(&file));
  po::options_description all;
  all.add(visible).add(hidden);
  po::positional_options_description positional;
  positional.add("file", 1);

  po::variables_map vm;
  if (!parse_options(argc, argv, all, vm, &positional, &visible)) return 0;
  const bool json = vm.count("json") > 0;

  if (!gearbox.empty()) {
    if (!file.empty()) throw po::error("give either FILE or --gearbox, not both");
    if (is_face_gear_description(gearbox)) return info_face_gear(gearbox, json);
    const diag::Gearbox gb = diag::load_gearbox(gearbox);
    print_warnings(gb.warnings(), "info");
    if (json) {
      std::cout << diag::summary_json(gb).dump(2) << "\n";
    } else {
      std::cout << diag::format_summary(gb) << "\n";
    }
    return 0;
  }
  if (file.empty()) throw po::error("missing FILE (or --gearbox GEARBOX.json)");

  diag::ImportOptions options;
  if (vm.count("fs")) options.fs_hz = vm["fs"].as<double>();
  if (file.size() > 5 && file.compare(file.size() - 5, 5, ".json") == 0) {
    throw diag::InputError(
        diag::format_error(file, "",
                           "a JSON file is not a recording; for a gearbox description use "
                           "`geardiag info --gearbox " +
                               file + "`"));
  }
  const Description d = describe(file, options);
  if (json) {
    std::cout << to_json(d).dump(2) << "\n";
  } else {
    print_text(d);
  }
  return 0;
}

}  // namespace geardiag
