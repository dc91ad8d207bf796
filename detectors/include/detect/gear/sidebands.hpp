// Gear-mesh sideband families: which shaft modulates a mesh.
//
// A local gear defect (a crack, a spall, eccentricity) modulates the mesh vibration in amplitude
// and phase once per revolution of the shaft carrying the gear; the mesh harmonics h f_mesh then
// carry sidebands at h f_mesh +- k f_shaft (McFadden & Smith 1985; Randall 1982, "A new method of
// modeling gear faults", J. Mech. Design 104; Lebold et al. 2000). Sidebands spaced at a shaft's
// rotation frequency point at that shaft (docs/physics.md, "Detectors").
//
// For each candidate shaft the amplitude spectrum is searched at h f_mesh +- k f_shaft,
// h = 1..mesh_harmonics, k = 1..sidebands, within +- search_bins bins (speed jitter, leakage); each
// line's floor is max(median of floor_bins bins on each side beyond the search window,
// precision_floor(spectrum, dynamic_range_db)) (fault_bands.hpp: the spectrum's largest value
// over the dynamic range, so no prominence exceeds dynamic_range_db, 120 dB by default). A line
// is detected when
//   (a) its prominence reaches line_threshold_db,
//   (b) its amplitude reaches min_sideband_to_mesh_db relative to the mesh's strongest harmonic
//       max_h A(h f_mesh), h = 1..H (a sideband significant for the mesh, not merely for a floor
//       that a noise-free record drives to zero), and
//   (c) it does not belong to the rest of the gearbox (SidebandContext): a line within
//       2 search_bins + 1 bins of another mesh's harmonic or of a combination tone
//       n1 f_mesh + n2 f_other (n1 = 0..H+1, n2 = +-1..+-(H+1)) is reported `shared`, never
//       detected (a healthy multi-stage box has those lines; they point at no shaft).
// The shaft's score is the sum of the detected lines' prominences [dB]; it passes with at least
// min_lines detected lines, at least one of them first-order (|k| = 1) when
// require_first_order: a modulation once per revolution of the shaft shows first at +-f_shaft,
// while lines only at k = +-2 (the even orders) are the orders of a shaft turning twice as fast
// (the three-shaft box: the input turns at twice the counter's rate). The shaft
// "pointed at" is the passing shaft with the highest score when it beats every other passing shaft
// by margin_db; otherwise the result is kAmbiguous, and kNoSidebands when no shaft passes.
//
// CAUTION: a line within the search window of another shaft's line is counted for both; the
// candidates' sideband lines must be more than 2 search_bins + 1 bins apart to be told apart
// (resolution: the bin spacing must be well below the difference of the shaft frequencies).
// Why min_sideband_to_mesh_db = -50 dB: amplitude modulation of depth m gives sidebands m/2 of the
// carrier, so -50 dB is m = 0.6 %. Below that a line is at the level of a measurement chain's
// non-linearity (accelerometer and conditioning 0.1-1 %: the mesh lines' intermodulation) and of
// the dynamic simulator's integration error (the healthy three-shaft box, noise-free, at
// 1500 rpm: shaft-order lines at -55 dB and below of the strongest mesh harmonic), not a defect's.
// A chipped tooth gives -40..-12 dB (tests/validation/healthy_noise_free_test.cpp).
// Threshold rationale as for diagnose_bearing_from_envelope (fault_bands.hpp): a noise bin exceeds
// 10 dB over the Rayleigh median with probability 1e-3, so a 5-bin window detects noise with ~0.5
// %; two such false lines among 2 K H = 18 windows happen with probability ~ C(18,2) 0.005^2 = 0.4
// %.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "detect/gear/fault_bands.hpp"

namespace detect {

struct ShaftCandidate {
  std::string name;
  double frequency_hz = 0;  // rotation frequency [Hz], > 0
};

struct SidebandOptions {
  int mesh_harmonics = 3;         // H: mesh harmonics examined, 1..20
  int sidebands = 3;              // K: sideband orders on each side, 1..20
  int search_bins = 2;            // peak search half-width [bins], 0..20
  int floor_bins = 20;            // floor window beyond the search window, each side [bins], >= 3
  double line_threshold_db = 10;  // a sideband line is detected at this prominence [dB], > 0
  int min_lines = 2;              // detected lines for a family to pass, >= 1
  double margin_db = 6;           // the winner's score over any other passing family's [dB], >= 0
  double min_sideband_to_mesh_db = -50;  // a line counts from this level relative to the
                                         // mesh's strongest harmonic [dB], [-200, 0]
  bool require_first_order = true;       // a passing family has a detected |k| = 1 line
  double dynamic_range_db = kDefaultDynamicRangeDb;  // floors no lower than the spectrum's
                                                     // largest value over this [dB],
                                                     // (line_threshold_db, 300]
  void validate() const;                             // throws diag::InputError naming the field
};

// The rest of the gearbox: lines that belong to it are not sidebands of a shaft.
struct SidebandContext {
  std::vector<double> other_mesh_hz;  // the gearbox's other mesh frequencies [Hz], each > 0
};

struct SidebandLine {
  int harmonic = 1;      // h
  int order = 1;         // k, signed: -1 is the first lower sideband
  LineMeasurement line;  // expected_hz = h f_mesh + k f_shaft
  bool shared = false;   // at another mesh's harmonic or a combination tone: never detected
  bool detected = false;
};

struct ShaftSidebands {
  std::string name;
  double frequency_hz = 0;
  std::vector<SidebandLine> lines;  // h ascending, then k = -K..-1, 1..K
  int detected = 0;
  double score_db = 0;  // sum of the detected lines' prominences
  bool passes = false;
};

enum class SidebandStatus {
  kNoSidebands,  // no candidate shaft has a passing sideband family
  kPointed,      // one shaft's family passes and beats the other passing families by margin_db
  kAmbiguous,    // two or more families pass within margin_db: no shaft is named
};

struct SidebandAnalysis {
  std::vector<LineMeasurement> mesh;   // h f_mesh, h = 1..H (valid == false beyond the spectrum)
  double mesh_reference = 0;           // max over the valid mesh lines' amplitudes (criterion (b))
  std::vector<ShaftSidebands> shafts;  // in the candidates' order
  SidebandStatus status = SidebandStatus::kNoSidebands;
  int pointed = -1;  // index into shafts when status == kPointed, else -1
};

// `spectrum`: an amplitude spectrum (uniform bins: the bin spacing is taken as
// (f_last - f_first) / (bins - 1)). Lines beyond the spectrum are reported invalid, not detected.
// Throws diag::InputError for a malformed spectrum, options, mesh_hz <= 0, a candidate's
// frequency <= 0 or another mesh's frequency <= 0.
SidebandAnalysis analyse_sidebands(const SpectrumView& spectrum, double mesh_hz,
                                   std::span<const ShaftCandidate> shafts,
                                   const SidebandOptions& opt = {},
                                   const SidebandContext& context = {});

}  // namespace detect
