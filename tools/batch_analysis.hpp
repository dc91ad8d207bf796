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

// The gearbox is `gearbox`, else the file's /gearbox, at the speed the data says. Reading is
// serialised (HDF5); the analysis is not. Throws diag::InputError naming the file.
FileAnalysis analyse_file(const std::string& file, const std::optional<diag::Gearbox>& gearbox,
                          const ChannelOptions& channels, std::optional<double> fs);

}  // namespace geardiag
