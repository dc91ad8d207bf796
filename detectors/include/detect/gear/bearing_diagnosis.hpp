// Rolling-bearing diagnosis of one vibration channel: prewhitening, a demodulation band from the
// fast kurtogram, the (squared) envelope spectrum and the fault decision of fault_bands.hpp, for
// every bearing given.
//
// Method (Randall & Antoni, "Rolling element bearing diagnostics - a tutorial", MSSP 25 (2011),
// sec. 3-4; the benchmark procedure of Smith & Randall, "Rolling element bearing diagnostics
// using the Case Western Reserve University data: a benchmark study", MSSP 64-65 (2015) 100-131):
//  1. Cepstral prewhitening (CPW; Sawalhi & Randall 2011; Borghesani et al., MSSP 36 (2013)):
//       x_w = IDFT( X_k / |X_k| ),
//     which flattens the spectrum, removing the discrete shaft / gear lines and the resonances'
//     colouring and leaving the impulsive part with its timing. (The real cepstrum set to zero at
//     every quefrency but 0 is the same operation.)
//  2. Fast kurtogram (kurtogram.hpp) of x_w; the band with the largest kurtosis among the
//     ALLOWED bands is chosen. A band is allowed when it is wide enough to carry the scored
//     harmonics as envelope content, bandwidth >= min_bandwidth_factor * harmonics * f_max, and
//     sits clear of the low-frequency shaft and fault lines, low edge >= min_band_low_factor *
//     f_max; f_max is the largest fault fundamental scored (BPFI or 2 BSF of any bearing).
//  3. Squared envelope spectrum (SES) of x_w in that band (Randall & Antoni 2011, sec. 3.2: the
//     squared envelope puts the fault rate's harmonics above the noise better than |z|).
//  4. diagnose_bearing (fault_bands.hpp) on the SES, for each bearing.
//  Steps 3-4 are repeated on the whole band of x_w (Smith & Randall's "CPW + SES" benchmark
//  method, which needs no band selection). The two decisions are combined conservatively: a
//  fault is reported only when BOTH name it; both finding nothing is kNoFault; anything else
//  (a family passing in one view only, different names, a tie) is kAmbiguous and reports
//  nothing. Two demodulations of different bands must agree: a chance alignment of noise lines
//  with a fault comb in one spectrum is not enough (on the CWRU ball-fault record, one view alone
//  would pass the outer-race family at 9 dB, just above the 8 dB threshold), and a real defect
//  comb shows in both (CWRU inner and outer race: 24-31 dB in each). Never the wrong fault.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>
#include <vector>

#include "detect/gear/fault_bands.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/recording.hpp"

namespace detect {

struct BearingDiagnosisOptions {
  bool prewhiten = true;              // cepstral prewhitening before everything else
  int kurtogram_max_level = 6;        // deepest kurtogram level, [1, 20] (the channel needs
                                      // 2^(level + 7) samples)
  double min_bandwidth_factor = 2.0;  // band width >= factor * harmonics * f_max, [0, 10]; 2:
                                      // both sidebands fc +- h f_max of a carrier at the band's
                                      // centre lie inside it, for every scored harmonic h
  double min_band_low_factor = 1.0;   // band low edge >= factor * f_max, [0, 100]: keeps
                                      // the fault and shaft lines themselves out of the band
  bool whole_band_check = true;       // also decide on the whole band and combine (see above)
  BearingDecisionOptions decision;    // the per-bearing decision (harmonics, thresholds, ...)

  void validate() const;  // throws diag::InputError "diagnose_bearings: <field>: ..."
};

struct BearingFinding {
  std::string bearing;      // BearingSpec::name
  std::string fault;        // "outer_race" | "inner_race" | "rolling_element" | "cage"
  double frequency_hz = 0;  // the family's fundamental (BPFO, BPFI, 2 BSF or FTF) [Hz]
  std::string channel;      // the channel's name
  double score_db = 0;      // the family's score in the band-selected SES [dB]
};

struct BearingStatus {
  std::string bearing;
  BearingDecisionStatus status = BearingDecisionStatus::kNoFault;  // the combined decision:
                                                                   // kAmbiguous when the two
                                                                   // views disagree
  BearingFault fault = BearingFault::kNone;                        // set when status == kFault
  BearingFrequencies frequencies;
  BearingDecision band_decision;   // on the SES of the kurtogram band
  BearingDecision whole_decision;  // on the SES of the whole band (empty when not checked)
};

struct BearingDiagnosis {
  std::vector<BearingFinding> findings;  // one per bearing with status kFault
  std::string channel;
  double band_centre_hz = 0;  // the demodulation band chosen from the kurtogram [Hz]
  double band_width_hz = 0;
  double band_level = 0;                // its kurtogram level
  double band_kurtosis = 0;             // its kurtosis (0 for Gaussian noise)
  std::vector<BearingStatus> bearings;  // in the order given
};

// The fault's name in findings: "outer_race", "inner_race", "rolling_element", "cage" ("" for
// kNone).
const char* finding_name(BearingFault f);

// channel: validated (diag::validate), at least 2^(kurtogram_max_level + 7) samples, not constant;
// shaft_hz: the inner ring's rotation frequency [Hz], > 0; bearings: at least one, each within
// BearingSpec's ranges. The allowed bands must not be empty (a too-low sampling rate for the
// fault frequencies throws diag::InputError saying so).
BearingDiagnosis diagnose_bearings(const diag::Signal& channel, double shaft_hz,
                                   std::span<const diag::BearingSpec> bearings,
                                   const BearingDiagnosisOptions& options = {});

// {"channel", "band": {"centre_hz", "bandwidth_hz", "level", "kurtosis"},
//  "findings": [{"bearing", "fault", "frequency_hz", "channel", "score_db"}],
//  "bearings": [{"bearing", "status", "fault", "families": [{"fault", "fundamental_hz",
//  "score_db", "detected", "passes"}], "whole_band_families": [...]}]}
nlohmann::json to_json(const BearingDiagnosis& diagnosis);

}  // namespace detect
