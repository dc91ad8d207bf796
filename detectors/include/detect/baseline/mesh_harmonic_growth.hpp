// Wear indicator against a healthy baseline: the growth of a mesh's harmonics, in dB.
//
// Flank wear takes the worn teeth away from conjugate action: the transmission error's mesh
// harmonics, and with them the vibration at h f_mesh, grow with the wear depth once it exceeds a
// couple of static deflections (sim/wear.hpp; docs/wear.md).
// The unit-free features of baseline.hpp normalise the level away and hardly move. This compares
// levels, channel by channel, against baseline recordings of the same gears:
//   A_h(c)  amplitude of channel c at h f_mesh, h = 1..harmonics: the largest bin of the Hann-
//           windowed, peak-scaled amplitude spectrum (detect::amplitude_spectrum, mean removed)
//           within +-search_bins of h f_mesh / resolution (speed tolerance and scalloping);
//   B_h(c)  the median of A_h(c) over the baseline recordings (each read at its own f_mesh);
//   g(c)    = 20 log10( rms_h A_h(c) / rms_h B_h(c) )                          [dB]
//   growth  = mean of g(c) over the recording's vibration channels (diag::sensor_channels) found in
//             every baseline recording;  flagged = growth > threshold_db.
// The mean over channels, not the largest: one channel near a structural resonance moves with
// the pitch errors of the particular gears (measured: up to 7.3 dB for healthy gears on one
// channel, 2 false alarms in 12 at 4 dB with the largest channel). Threshold 4 dB
// (docs/validation.md, "Wear indicator against a baseline"; the scripts in docs/wear_indicator/):
// ISO 1328 grade 6 pitch errors and 8 um runout, baseline 3 recordings at 0.95-1.05 x torque; tuned
// on 29/47 seeds 1-6 (largest healthy growth 0.78 dB + 3 dB), reported on 29/47 seeds 7-12 and a
// 23/41 x 19/53 gearbox seeds 1-6: healthy (1.1 x torque, 0.95 / 1.05 x speed, other gears of the
// same grade) 0 of 48 flagged, largest 2.0 dB; worn 20, 40, 54 um flagged 12 of 12 each (5.3-15.7
// dB), 10 um 0 of 12, 5 um 0 of 12 (light wear first lowers the harmonics). The baseline should be
// within a few percent of the recording's speed (5 % moves the growth by up to 2 dB).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "diag/io/recording.hpp"

namespace detect {

struct MeshHarmonicGrowthOptions {
  int harmonics = 3;          // h = 1..harmonics, [1, 20]; every h f_mesh must lie below fs / 2
  int search_bins = 2;        // +-bins searched around h f_mesh, [0, 50]
  double threshold_db = 4.0;  // flagged above it, > 0 (validated above)

  void validate() const;  // throws diag::InputError "mesh_harmonic_growth: <field>: ..."
};

struct MeshHarmonicGrowth {
  double growth_db = 0;  // mean over the channels below
  bool flagged = false;  // growth_db > threshold_db
  double threshold_db = 0;
  std::vector<std::string> channels;  // the channels compared
  std::vector<double> channel_db;     // g(c), same order
};

// rec and every baseline recording with their mesh frequency [Hz] at the speed they ran
// (baseline_mesh_hz[i] for baseline[i]). Throws diag::InputError for an empty baseline, sizes that
// differ, a non-positive frequency, a harmonic at or above a channel's fs / 2, no vibration
// channel shared with every baseline recording, or a baseline level of zero.
MeshHarmonicGrowth mesh_harmonic_growth(const diag::Recording& rec, double mesh_hz,
                                        std::span<const diag::Recording> baseline,
                                        std::span<const double> baseline_mesh_hz,
                                        const MeshHarmonicGrowthOptions& options = {});

}  // namespace detect
