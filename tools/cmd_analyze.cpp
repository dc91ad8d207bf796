// geardiag analyze: offline analysis of a recording into a readable summary, a JSON report and a
// self-contained HTML report (detect/analysis). Exit 0 on success (findings or not, unless
// --fail-on), 1 with --fail-on when its condition holds, 4 with --fail-on when it does not but
// not every sample was examined (--max-samples, frames that could not be analysed), 2 on bad
// input.
#include <unistd.h>

#include <boost/program_options.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "allocator.hpp"
#include "channel_options.hpp"
#include "cli_options.hpp"
#include "commands.hpp"
#include "detect/analysis/analyze.hpp"
#include "detect/analysis/analyze_file.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/data_groups.hpp"
#include "output.hpp"
#include "report/curves.hpp"
#include "report/html_report.hpp"
#include "report/report.hpp"

namespace po = boost::program_options;

namespace geardiag {

int cmd_analyze(int argc, char** argv) {
  tune_allocator_for_recordings();
  detect::AnalyzeRequest request;
  detect::AnalyzeOptions& opt = request.options;
  const detect::BaselineComparisonOptions& bo = request.baseline_options;
  std::string recording, gearbox, json_out, html_out, fail_on, curves_out;
  std::vector<std::string> baselines;
  std::vector<std::string> gear_baselines;
  double fs_hz = 0;
  std::uint64_t max_samples = 0;
  ChannelOptions channels;
  po::options_description desc(
      "geardiag analyze RECORDING [--gearbox GB.json] [--fs HZ] [--baseline FILE...] "
      "[--gear-baseline FILE...] "
      "[--json OUT.json] [--html OUT.html] [--curves OUT.h5] [--fail-on alarm|finding]\n\n"
      "RECORDING: a geardiag HDF5 recording, or CSV (.csv, .csv.gz), WAV or MAT measurements\n"
      "(imported as by `geardiag import`; --fs for CSV without a time column and for MAT).\n"
      "The gearbox description comes from --gearbox, else from the recording's /gearbox; without\n"
      "one only the unit-free indicators and spectra are computed. Reports: --json (stable keys,\n"
      "amplitudes in each channel's unit) and --html (one self-contained file).\n"
      "--baseline: healthy recordings of the same machine and channels, read like RECORDING\n"
      "(same --fs); each is cut into " +
      std::to_string(bo.segments_per_recording) +
      " parts, the unit-free features of every common channel are compared\n"
      "(robust z), anomaly_score = mean z^2, alarm above " +
      std::to_string(static_cast<int>(bo.baseline.alarm_threshold)) +
      ".\nOutputs are checked before the analysis starts. '-' writes a report to stdout; the\n"
      "summary then goes to stderr. Exit 1 with --fail-on: alarm = the baseline alarm was raised;\n"
      "finding = any finding or the baseline alarm; exit 4 with --fail-on when it does not hold\n"
      "but not every sample was examined (--max-samples, frames that could not be analysed).\n"
      "Every sample is examined: a long recording frame by frame (at most " +
      std::to_string(detect::kDefaultMaxSamples) +
      " samples per frame),\nits findings placed in time (time_s, segments).\n"
      "--gear-baseline: healthy recordings of the same gears at about the same speed and load;\n"
      "the damaged-shaft locator subtracts their revolution averages (NA4-style; of several, per\n"
      "shaft the one that leaves the least) and fuses that answer with the recording's own\n"
      "(different shafts: ambiguous, both reported).\n\n"
      "options");
  desc.add_options()("help,h", "this help")("recording", po::value(&recording)->required(),
                                            "recording (.h5, .csv, .csv.gz, .wav, .mat)")(
      "gearbox", po::value(&gearbox), "gearbox description (JSON)")(
      "fs", po::value(&fs_hz), "sampling rate [Hz] for CSV without time column / MAT, > 0")(
      "baseline", po::value(&baselines)->multitoken(),
      "healthy recordings to compare with (same channels and sampling rate)")(
      "gear-baseline", po::value(&gear_baselines)->multitoken(),
      "healthy recordings (same gears, about the same speed and load) for the damaged-shaft "
      "locator")("json", po::value(&json_out),
                 "write the analysis as JSON to this file ('-': stdout)")(
      "html", po::value(&html_out),
      "write a self-contained HTML report to this file ('-': stdout)")(
      "fail-on", po::value(&fail_on),
      "exit 1 when: alarm (the baseline alarm; needs --baseline) | finding (any finding or the "
      "baseline alarm); else 4 when not every sample was examined")(
      "mesh-harmonics",
      po::value(&opt.sidebands.mesh_harmonics)->default_value(opt.sidebands.mesh_harmonics),
      "mesh harmonics examined for sidebands, 1..20")(
      "sidebands", po::value(&opt.sidebands.sidebands)->default_value(opt.sidebands.sidebands),
      "sideband orders on each side, 1..20")(
      "tacho-ppr", po::value(&opt.tacho_pulses_per_rev)->default_value(opt.tacho_pulses_per_rev),
      "tacho pulses per shaft revolution for every tacho, [0, 1e5]; 0: each tacho's own")(
      "tsa-min-revs", po::value(&opt.tsa_min_revolutions)->default_value(opt.tsa_min_revolutions),
      "fewer whole revolutions skip a shaft's TSA, >= 2")(
      "threads", po::value(&opt.threads)->default_value(opt.threads),
      "frames of a long recording, else channels, analysed in parallel, [0, 256]; 0: one per "
      "hardware thread (default; 2 for a recording of several frames)")(
      "welch-nperseg", po::value(&opt.welch_nperseg)->default_value(opt.welch_nperseg),
      "Welch segment length [samples], [8, 2^24]");
  desc.add_options()("curves", po::value(&curves_out),
                     "write every curve the report draws (PSD, spectra, envelope spectra with the "
                     "fault bands, order spectra, TSA signals, speed) as HDF5 datasets with their "
                     "axes and units (docs/report.md)");
  const std::string max_samples_help =
      "an opt-in limit: analyse only the first part of the recording holding at most this many "
      "samples in all (or " +
      std::to_string(detect::kKeptChannelSamples) + " per channel, never over " +
      std::to_string(detect::kMaxChannelSamples) +
      " per channel); the rest is reported as not examined. 0 (default): every sample";
  desc.add_options()("max-samples", po::value(&max_samples)->default_value(max_samples),
                     max_samples_help.c_str());
  desc.add_options()(
      "frame-seconds", po::value(&request.frame_s)->default_value(request.frame_s),
      "frames of at most this length [s] (a finer timeline: findings are placed to within a "
      "frame; each frame must hold what its stages need, e.g. the TSA's revolutions); 0: as "
      "long as memory allows");
  desc.add_options()(
      "load", po::value(&request.load_channel),
      "a channel whose RMS level is the machine's load (a torque, a motor current): a long "
      "log's frames are also cut where it steps by more than 5 %");
  desc.add_options()("timing", po::bool_switch(&opt.timing),
                     "add the time of each stage to the JSON (timing_s: wall time per stage, "
                     "CPU time per channel stage)")(
      "rpm-at", po::value(&opt.nominal_time_s),
      "time [s] at which the nominal (or --rpm) speed holds, for the speed from the vibration "
      "of a run-up without a tacho; default: a steady record, else mid-record");
  channels.add_to(desc, true);
  po::positional_options_description pos;
  pos.add("recording", 1);
  po::variables_map vm;
  if (!parse_options(argc, argv, desc, vm, &pos)) return 0;
  if (vm.count("fs") && !(fs_hz > 0 && std::isfinite(fs_hz))) {
    throw diag::InputError("--fs: " + std::to_string(fs_hz) + " is not a sampling rate > 0 Hz");
  }
  if (vm.count("fail-on") && fail_on != "alarm" && fail_on != "finding") {
    throw diag::InputError("--fail-on: '" + fail_on + "' is not alarm or finding");
  }
  if (fail_on == "alarm" && baselines.empty()) {
    throw diag::InputError("--fail-on alarm: an alarm needs --baseline recordings to compare with");
  }
  // Outputs are checked before the (possibly long) analysis.
  const bool json_stdout = !json_out.empty() && check_output(json_out, "--json");
  const bool html_stdout = !html_out.empty() && check_output(html_out, "--html");
  const bool curves_stdout = !curves_out.empty() && check_output(curves_out, "--curves");
  if (int(json_stdout) + int(html_stdout) + int(curves_stdout) > 1) {
    throw diag::InputError("--json, --html, --curves: only one report can go to stdout ('-')");
  }
  if (vm.count("fs")) request.fs_hz = fs_hz;
  const std::filesystem::path path(recording);
  request.recording = path;
  request.max_samples = max_samples;
  for (const std::string& b : baselines) request.baseline.emplace_back(b);
  for (const std::string& g : gear_baselines) {
    if (!request.gear_baseline) {
      request.gear_baseline = detect::RecordingInput(g);
    } else {
      request.more_gear_baselines.emplace_back(g);
    }
  }
  if (!gearbox.empty()) request.gearbox = diag::load_gearbox(gearbox);
  request.channels = channels;
  // The plot-only curves are computed for a plot only (detect::AnalyzeOptions::traces).
  opt.traces = !html_out.empty() || !curves_out.empty();
  // A progress line on a terminal only: piped or redirected, stderr stays quiet.
  const bool terminal = ::isatty(STDERR_FILENO) != 0;
  if (terminal) {
    opt.progress = [&](const std::string& stage) {
      std::fprintf(stderr, "\ranalyze %s: %-32s", path.filename().string().c_str(), stage.c_str());
      std::fflush(stderr);
    };
  }
  detect::FileAnalysis analysis = detect::analyze_file(request);
  if (terminal) std::fprintf(stderr, "\r%-80s\r", "");
  const detect::AnalysisResult& r = analysis.result;
  // stdout carries nothing but a report sent there, so that it stays valid JSON or HTML.
  (json_stdout || html_stdout || curves_stdout ? std::cerr : std::cout)
      << report::format_summary(r);
  if (!json_out.empty()) write_output(json_out, report::to_json(r).dump(2) + "\n", "--json");
  if (!html_out.empty()) {
    report::HtmlReportOptions ho;
    ho.source = path.filename().string();
    ho.title = "geardiag analysis: " + path.filename().string();
    write_output(html_out, report::render_html_report(r, ho), "--html");
  }
  if (!curves_out.empty()) {
    diag::write_data_groups(curves_out, report::analysis_curves(r),
                            {{"source", path.filename().string()}}, "--curves");
  }
  const bool alarm = r.baseline && r.baseline->alarm;
  const bool holds = fail_on == "alarm" ? alarm : alarm || !r.findings.empty();
  if (fail_on.empty()) return 0;
  if (holds) return 1;
  // Silence about what was not examined is not a pass.
  return r.coverage && !r.coverage->complete() ? kExitNotExamined : 0;
}

}  // namespace geardiag
