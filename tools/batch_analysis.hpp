// One file analysed as `geardiag analyze` does, single-threaded (the caller runs many files in
// parallel): shared by `batch` and `validate --dataset`.
#pragma once

#include <optional>
#include <string>

#include "channel_options.hpp"
#include "detect/analysis/analyze.hpp"
#include "diag/gearbox/gearbox.hpp"

namespace geardiag {

struct FileAnalysis {
  diag::Recording recording;  // as prepared for the analysis (channel roles, tachos)
  detect::AnalysisResult result;
};

// `recording` (read from `file` by the caller: load_recording, recording_input.hpp, on a thread
// of its own, parallel.hpp's run_in_rounds) analysed. The gearbox is `gearbox`, else the file's
// /gearbox, at the speed the data says. Throws diag::InputError naming the file.
FileAnalysis analyse_file(diag::Recording recording, const std::string& file,
                          const std::optional<diag::Gearbox>& gearbox,
                          const ChannelOptions& channels);

}  // namespace geardiag
