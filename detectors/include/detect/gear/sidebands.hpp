// Gear-mesh sideband families: which shaft modulates a mesh.
//
// A local gear defect (a crack, a spall, eccentricity) modulates the mesh vibration in amplitude
// and phase once per revolution of the shaft carrying the gear; the mesh harmonics h f_mesh then
// carry sidebands at h f_mesh +- k f_shaft (McFadden & Smith 1985; Randall 1982, "A new method of
// modeling gear faults", J. Mech. Design 104; Lebold et al. 2000). Sidebands spaced at a shaft's
// rotation frequency point at that shaft (SPEC.md, "The detectors").
//
// For each candidate shaft the amplitude spectrum is searched at h f_mesh +- k f_shaft,
// h = 1..mesh_harmonics, k = 1..sidebands, within +- search_bins bins (speed jitter, leakage); each
// line's floor is the median of floor_bins bins on each side beyond the search window; a line is
// detected when its prominence reaches line_threshold_db. The shaft's score is the sum of the
// detected lines' prominences [dB]; it passes with at least min_lines detected lines. The shaft
// "pointed at" is the passing shaft with the highest score when it beats every other passing shaft
// by margin_db; otherwise the result is kAmbiguous, and kNoSidebands when no shaft passes.
//
// CAUTION: a line within the search window of another shaft's line is counted for both; the
// candidates' sideband lines must be more than 2 search_bins + 1 bins apart to be told apart
// (resolution: the bin spacing must be well below the difference of the shaft frequencies).
// Threshold rationale as for diagnose_bearing (fault_bands.hpp): a noise bin exceeds 10 dB over
// the Rayleigh median with probability 1e-3, so a 5-bin window detects noise with ~0.5 %; two such
// false lines among 2 K H = 18 windows happen with probability ~ C(18,2) 0.005^2 = 0.4 %.
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
  void validate() const;          // throws diag::InputError naming the field
};

struct SidebandLine {
  int harmonic = 1;      // h
  int order = 1;         // k, signed: -1 is the first lower sideband
  LineMeasurement line;  // expected_hz = h f_mesh + k f_shaft
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
  std::vector<ShaftSidebands> shafts;  // in the candidates' order
  SidebandStatus status = SidebandStatus::kNoSidebands;
  int pointed = -1;  // index into shafts when status == kPointed, else -1
};

// `spectrum`: an amplitude spectrum (uniform bins: the bin spacing is taken as
// (f_last - f_first) / (bins - 1)). Lines beyond the spectrum are reported invalid, not detected.
// Throws diag::InputError for a malformed spectrum, options, mesh_hz <= 0 or a candidate's
// frequency <= 0.
SidebandAnalysis analyse_sidebands(const SpectrumView& spectrum, double mesh_hz,
                                   std::span<const ShaftCandidate> shafts,
                                   const SidebandOptions& opt = {});

}  // namespace detect
