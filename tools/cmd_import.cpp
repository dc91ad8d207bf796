// geardiag import INPUT [--fs HZ] -o OUTPUT.h5: measured data (CSV, CSV.gz, WAV and other
// libsndfile formats, MATLAB .mat, geardiag HDF5) to a geardiag HDF5 recording.
#include <boost/program_options.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "channel_options.hpp"
#include "cli_options.hpp"
#include "commands.hpp"
#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/channels.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/import.hpp"
#include "output.hpp"

namespace geardiag {

namespace po = boost::program_options;

namespace {

void print_channel(std::FILE* to, const diag::Signal& s, const char* group) {
  std::fprintf(to, "  %-24s %-8s %10zu samples  %12.6g Hz  %10.3f s  %s%s\n", s.name.c_str(), group,
               s.samples.size(), s.fs_hz, s.duration_s(),
               std::string(diag::to_string(s.role)).c_str(),
               s.shaft.empty() ? "" : (" (" + s.shaft + ")").c_str());
}

}  // namespace

int cmd_import(int argc, char** argv) {
  const diag::Hdf5WriteOptions write_defaults;
  diag::Hdf5WriteOptions write_options;
  std::string input, output, gearbox;
  ChannelOptions channels;

  po::options_description visible(
      "usage: geardiag import INPUT -o OUTPUT.h5 [--fs HZ] [--gearbox GB.json] [--channels "
      "MAP.json]\n"
      "       [--tacho CHANNEL=SHAFT[:PPR]]...\n\n"
      "Converts every numeric channel of INPUT to a geardiag HDF5 recording.\n"
      "INPUT: .csv / .csv.gz (header row; a column time, t, time_s or time_sec [s] gives the\n"
      "sampling rate), .wav / .flac / ... (libsndfile), .mat (MATLAB v5: vectors become channels,\n"
      "scalars metadata), .h5 (a geardiag recording).\n\noptions");
  visible.add_options()             //
      ("help,h", "show this help")  //
      ("output,o", po::value<std::string>(&output)->value_name("FILE"),
       "HDF5 recording to write (required; '-': stdout, the listing then goes to stderr)")  //
      ("fs", po::value<double>()->value_name("HZ"),
       "sampling rate [Hz], > 0: required for .mat and for CSV without a time column; checked "
       "against a CSV time column (0.1 %); replaces a sound file's rate")  //
      ("chunk-samples",
       // Read signed and checked: an unsigned option would take -1 as 2^64 - 1.
       po::value<long long>()
           ->default_value(static_cast<long long>(write_defaults.chunk_samples))
           ->value_name("N")
           ->notifier([&](long long v) {
             constexpr long long kMaxChunk = 1LL << 24;
             if (v < 1 || v > kMaxChunk) {
               throw diag::InputError("--chunk-samples: " + std::to_string(v) + " is not in [1, " +
                                      std::to_string(kMaxChunk) + "]");
             }
             write_options.chunk_samples = static_cast<std::size_t>(v);
           }),
       "HDF5 chunk length [samples], 1 ... 16777216")  //
      ("deflate",
       po::value<int>(&write_options.deflate_level)
           ->default_value(write_defaults.deflate_level)
           ->value_name("LEVEL"),
       "gzip compression level, 0 (off) ... 9")  //
      ("gearbox", po::value<std::string>(&gearbox)->value_name("GB.json"),
       "gearbox description: stored with the recording; lets tacho columns be recognised by "
       "their rate");
  channels.add_to(visible, false);
  po::options_description hidden;
  hidden.add_options()("input", po::value<std::string>(&input));
  po::options_description all;
  all.add(visible).add(hidden);
  po::positional_options_description positional;
  positional.add("input", 1);

  po::variables_map vm;
  if (!parse_options(argc, argv, all, vm, &positional, &visible)) return 0;
  if (input.empty()) throw po::error("missing INPUT file");
  if (output.empty()) throw po::error("missing -o OUTPUT.h5");

  diag::ImportOptions options;
  if (vm.count("fs")) options.fs_hz = vm["fs"].as<double>();

  // Checked before the import, which can take long for a large file.
  const bool to_stdout = check_output(output, "--output");
  std::error_code ec;
  if (!to_stdout && std::filesystem::equivalent(input, output, ec)) {
    throw diag::InputError(
        diag::format_error(output, "", "the output would overwrite the input file"));
  }
  std::optional<diag::Gearbox> gb;
  if (!gearbox.empty()) gb = diag::load_gearbox(gearbox);
  diag::Recording rec = diag::import_recording(input, options);
  const std::vector<std::string> notes = diag::prepare_channels(rec, gb ? &*gb : nullptr, channels);
  if (gb) {
    rec.gearbox_json = gb->description_json();
    // Every channel was looked at with the description: what inference did not take as a tacho
    // is vibration, and stays so when the file is analysed.
    rec.roles_stated = true;
  }
  diag::write_recording(output, rec, write_options);

  std::FILE* listing = to_stdout ? stderr : stdout;
  for (const auto& s : rec.signals) print_channel(listing, s, "signals");
  for (const auto& s : rec.tachos) print_channel(listing, s, "tacho");
  for (const auto& n : notes) std::fprintf(listing, "note: %s\n", n.c_str());
  std::fprintf(listing, "wrote %s (%zu channels)\n", output.c_str(),
               rec.signals.size() + rec.tachos.size());
  return 0;
}

}  // namespace geardiag
