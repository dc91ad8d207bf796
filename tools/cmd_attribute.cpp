// geardiag attribute: which gear (or shaft) carries each sporadic defect, from the input and
// output shaft angles (seed 003). Exit 0 when every event is explained (or none is found), 1 when
// some events match no recurrence period (multiplicity: several defects, not separable).
#include <boost/program_options.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_options.hpp"
#include "commands.hpp"
#include "detect/attribution/period_matcher.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/import.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/io/truth.hpp"
#include "diag/units.hpp"
#include "output.hpp"

namespace po = boost::program_options;

namespace geardiag {

namespace {

// Angle-domain CSV needs no sampling rate; the importer wants one unless a time column gives it.
bool csv_has_time_column(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string header;
  std::getline(in, header);
  std::stringstream fields(header);
  std::string f;
  while (std::getline(fields, f, ',')) {
    while (!f.empty() && (f.back() == '\r' || f.back() == ' ')) f.pop_back();
    for (auto& c : f) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (f == "time" || f == "t" || f == "time_s" || f == "time_sec") return true;
  }
  return false;
}

}  // namespace

namespace {

// The simulated truth stored with a recording (diag/io/truth.hpp): a /truth that is not JSON or
// whose defects have other types is an InputError naming the recording, never a crash.
void print_truth(const std::string& text, const std::string& recording) {
  const auto truth = diag::parse_truth(text, recording);
  if (!truth || truth->defects.empty()) return;
  std::cout << "truth (simulated recording):\n";
  for (const diag::TruthDefect& d : truth->defects) {
    std::cout << "  " << d.gear << " on " << d.shaft << ": " << diag::to_string(d.kind);
    if (!std::isnan(d.period_input_rev))
      std::cout << ", period " << d.period_input_rev << " input rev";
    if (!std::isnan(d.size_output_rad)) {
      std::cout << ", size at output " << diag::units::rad_to_deg(d.size_output_rad) << " deg";
    }
    std::cout << "\n";
  }
}

}  // namespace

int cmd_attribute(int argc, char** argv) {
  detect::AttributionOptions opt;
  std::string recording, gearbox, json_out;
  po::options_description desc(
      "geardiag attribute RECORDING [--gearbox GB.json] [--json OUT.json] [options]\n\n"
      "RECORDING: an HDF5 recording with channels input_angle_rad and output_angle_rad, or a CSV\n"
      "with the header input_angle_rad,output_angle_rad. The gearbox description comes from\n"
      "--gearbox, else from the recording's /gearbox. Exit 1 when some events match no period\n"
      "(multiplicity).\n\noptions");
  desc.add_options()("help,h", "this help")("recording", po::value(&recording)->required(),
                                            "recording (.h5) or angle CSV")(
      "gearbox", po::value(&gearbox), "gearbox description (JSON)")(
      "json", po::value(&json_out), "write the findings as JSON to this file ('-': stdout)")(
      "tolerance", po::value(&opt.period_tolerance)->default_value(opt.period_tolerance),
      "relative tolerance of a period match, (0, 0.2]")(
      "threshold-sigma", po::value(&opt.threshold_sigma)->default_value(opt.threshold_sigma),
      "event threshold in robust noise sigmas, >= 3")(
      "min-coverage", po::value(&opt.min_coverage)->default_value(opt.min_coverage),
      "share of recurrences a train must show, (0, 1]")(
      "position-tolerance-rad",
      po::value(&opt.position_tolerance_rad)->default_value(opt.position_tolerance_rad),
      "input-angle tolerance of a recurrence [rad]; 0 = automatic");
  po::positional_options_description pos;
  pos.add("recording", 1);
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm, &pos)) return 0;
  // Checked before the work; with "-" the JSON goes to stdout and the table to stderr.
  const CoutToStderr table_to_stderr(!json_out.empty() && check_output(json_out, "--json"));

  const std::filesystem::path path(recording);
  diag::Recording rec;
  if (diag::is_hdf5_file(path)) {
    rec = diag::read_recording(path);
  } else {
    diag::ImportOptions io;
    if (std::filesystem::exists(path) && !csv_has_time_column(path)) io.fs_hz = 1.0;  // unused
    rec = diag::import_recording(path, io);
  }
  const diag::Signal& in = rec.require("input_angle_rad", recording);
  const diag::Signal& out = rec.require("output_angle_rad", recording);
  diag::Gearbox gb = [&] {
    if (!gearbox.empty()) return diag::load_gearbox(gearbox);
    if (rec.gearbox_json.empty()) {
      throw diag::InputError(recording + ": holds no gearbox description; give --gearbox");
    }
    return diag::parse_gearbox_text(rec.gearbox_json, recording + ": /gearbox");
  }();
  print_warnings(gb.warnings(), "attribute");
  detect::AttributionResult r;
  try {
    r = detect::attribute_defects(in.samples, out.samples, gb, opt);
  } catch (const diag::InputError& e) {
    throw diag::InputError(recording + ": " + e.what());
  }
  std::cout << detect::format_table(r);
  if (!rec.truth_json.empty()) print_truth(rec.truth_json, recording);
  if (!json_out.empty()) {
    nlohmann::json j = detect::to_json(r);
    j["warnings"] = gb.warnings();
    write_output(json_out, j.dump(2) + "\n", "--json");
  }
  return r.multiplicity ? 1 : 0;
}

}  // namespace geardiag
