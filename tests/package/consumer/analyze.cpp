// analyze.cpp (docs/install.md): what `geardiag analyze REC [--gearbox GB.json] --json -` prints.
#include <cstdio>
#include <geardiag/geardiag.hpp>

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  detect::AnalyzeRequest request;
  request.recording = std::filesystem::path(argv[1]);
  if (argc > 2) request.gearbox = diag::load_gearbox(argv[2]);
  request.options.traces = false;  // no plot: the plot-only curves are not computed
  try {
    const detect::FileAnalysis a = detect::analyze_file(request);
    std::fputs(report::format_summary(a.result).c_str(), stderr);
    std::puts(report::to_json(a.result).dump(2).c_str());
  } catch (const diag::InputError& e) {  // bad input: the message names the file and field
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
