// A user's program: reads a recording (CSV, WAV, MAT or HDF5, by its path alone), computes the
// Welch PSD of its first signal and prints what a test can check: the signal, the PSD's bin count
// and the frequency of its largest bin.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <geardiag/geardiag.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer RECORDING\n");
    return 2;
  }
  try {
    const diag::Recording rec = diag::open_recording(argv[1]);
    if (rec.signals.empty()) {
      std::fprintf(stderr, "%s: no signal\n", argv[1]);
      return 2;
    }
    const diag::Signal& s = rec.signals.front();
    detect::WelchOptions options;
    options.fs_hz = s.fs_hz;
    options.nperseg = 256;
    const detect::Psd psd = detect::welch(s.samples, options);
    const auto peak = std::max_element(psd.value.begin(), psd.value.end()) - psd.value.begin();
    std::printf("geardiag %s\n", diag::version());
    std::printf("signal %s: %zu samples at %g Hz\n", s.name.c_str(), s.samples.size(), s.fs_hz);
    std::printf("psd: %zu bins, %zu segments, peak at %g Hz\n", psd.value.size(), psd.segments,
                psd.frequency_hz[static_cast<std::size_t>(peak)]);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
