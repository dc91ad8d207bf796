// Rolling-bearing diagnosis of one vibration channel: prewhitening, a demodulation band from the
// fast kurtogram, the (squared) envelope spectrum and the fault decision of fault_bands.hpp, for
// every bearing given.
//
// Method (Randall & Antoni, "Rolling element bearing diagnostics - a tutorial", MSSP 25 (2011),
// sec. 3-4; the benchmark procedure of Smith & Randall, "Rolling element bearing diagnostics
// using the Case Western Reserve University data: a benchmark study", MSSP 64-65 (2015) 100-131):
//  0. The record is cut to its middle fast_length_at_most(n) samples (envelope.hpp: the largest
//     2^a 3^b 5^c 7^d <= n, at most 1/64 of the samples dropped for n >= 2^16), so that its
//     whole-record DFTs run at FFTW's full speed (a CWRU record of 121265 = 5 x 79 x 307 samples
//     took 12 times longer per DFT than 120960).
//  1. Cepstral prewhitening (CPW; Sawalhi & Randall 2011; Borghesani et al., MSSP 36 (2013)):
//       x_w = IDFT( X_k / |X_k| ),
//     which flattens the spectrum, removing the discrete shaft / gear lines and the resonances'
//     colouring and leaving the impulsive part with its timing. (The real cepstrum set to zero at
//     every quefrency but 0 is the same operation.)
//  2. Fast kurtogram (kurtogram.hpp) of x_w; the band with the largest kurtosis among the
//     ALLOWED bands is chosen. A band is allowed when it is wide enough to carry the scored
//     harmonics as envelope content, bandwidth >= min_bandwidth_factor * harmonics * f_max, and
//     sits clear of the low-frequency shaft and fault lines, low edge >= min_band_low_factor *
//     f_max; f_max is the largest fault fundamental scored (BPFI or 2 BSF of any bearing). Only
//     the allowed bands are computed (KurtogramOptions::min_bandwidth_hz, min_low_hz).
//  3. Squared envelope spectrum (SES) of x_w in that band (Randall & Antoni 2011, sec. 3.2: the
//     squared envelope puts the fault rate's harmonics above the noise better than |z|), from
//     the prewhitening's own DFT X / |X| (envelope.hpp squared_envelope_spectrum: exact at fewer
//     samples, |z|^2 being band-limited).
//  4. diagnose_bearing_from_envelope (fault_bands.hpp) on the SES, for each bearing.
//  Steps 3-4 are repeated on the whole band of x_w (Smith & Randall's "CPW + SES" benchmark
//  method, which needs no band selection). The two decisions are combined conservatively:
//   - both name the same fault: kFault ("both_views");
//   - one names a fault F clearly (every scored harmonic detected, score >= single_view_score_db)
//     and the other names nothing (kNoFault), and F's comb is supported in
//     the other view (comb_support in fault_bands.hpp: its lines at the fundamental found in the
//     first view, up to support_harmonics of them, stand above every detuned comb of the same
//     spectrum): kFault ("band_view_comb_support" or "whole_view_comb_support"). This is the
//     weak-family case: a defect whose comb stands 3-7 dB over the floor of the whole band's
//     SES, under the line threshold, while the kurtogram band's SES shows it clearly (Smith &
//     Randall 2015 find such records among the outer-race faults);
//   - both name nothing: kNoFault;
//   - anything else (a family in one view only without comb support, different names, a tie, the
//     ball lines without their cage-rate modulation) is kAmbiguous and names nothing.
//  A chance alignment of noise lines with a fault comb in one spectrum is not enough (on the CWRU
//  ball-fault record one view alone passes the outer-race family at 9 dB), and a real defect comb
//  shows in both (CWRU inner and outer race: 24-31 dB in each). Never the wrong fault: a wrong
//  claim costs more than a silence.
//  FTF lines alone give a cage note (BearingStatus::note), never a finding (fault_bands.hpp).
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>
#include <vector>

#include "detect/finding.hpp"
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
  double single_view_score_db = 10;   // a fault named by one view alone (comb support in the
                                      // other) needs every harmonic detected and this score
                                      // [dB], > 0. Why 15: the CWRU ball-fault record passes the
                                      // outer-race family in the kurtogram band's view at 9 dB
                                      // (2 of 3 harmonics) with a comb in the whole band's view;
                                      // the defect combs this path is for stand 15-30 dB there
  BearingDecisionOptions decision;    // the per-bearing decision (harmonics, thresholds, ...)

  void validate() const;  // throws diag::InputError "diagnose_bearings: <field>: ..."
};

// The evidence behind a finding, from the view(s) that name it.
struct BearingEvidence {
  std::string family;              // "BPFO" | "BPFI" | "2xBSF"
  std::string basis;               // "both_views" | "band_view_comb_support" |
                                   // "whole_view_comb_support"
  int harmonics_seen = 0;          // detected harmonics in the naming view (the band view when
                                   // both name it)
  int harmonics_scored = 0;        // harmonics looked at
  std::vector<double> line_db;     // prominence of each harmonic there [dB]
  double sideband_hz = 0;          // f_r (BPFI), FTF (2 BSF), 0 (BPFO)
  int sidebands_seen = 0;          // around the detected harmonics, in the naming view
  int ftf_lines_seen = 0;          // 2 BSF: detected FTF lines in the naming view
  double other_view_score_db = 0;  // the family's score in the other view [dB]
  double support_db = 0;           // comb statistic in the other view (comb-support basis) [dB]
  double support_null_db = 0;      // the largest detuned comb there [dB]
};

// The findings (finding.hpp) are kind "bearing": fault (outer_race, inner_race,
// rolling_element), bearing (BearingSpec::name), channel, frequency_hz (the family's nominal
// fundamental: BPFO, BPFI or 2 BSF), confidence 1 when both views name it, 0.5 for one view with
// the comb's support in the other, note "<family> (<basis>)", and the evidence's numbers:
// "score_db" (the family's score in the naming view(s), the larger [dB]), "harmonics_seen",
// "harmonics_scored", "sideband_hz", "sidebands_seen", "ftf_lines_seen", "other_view_score_db",
// "support_db", "support_null_db" (BearingEvidence; its family, basis and line_db are in the
// bearing's BearingStatus::evidence).
struct BearingStatus {
  std::string bearing;
  BearingDecisionStatus status = BearingDecisionStatus::kNoFault;  // the combined decision:
                                                                   // kAmbiguous when the two
                                                                   // views disagree
  BearingFault fault = BearingFault::kNone;                        // set when status == kFault
  BearingFrequencies frequencies;
  BearingDecision band_decision;   // on the SES of the kurtogram band
  BearingDecision whole_decision;  // on the SES of the whole band (empty when not checked)
  CombSupport support;       // of the one view's fault in the other view, when one view alone names
                             // it (see the combination above); empty otherwise
  BearingEvidence evidence;  // the evidence behind the fault, when status == kFault
  std::string note;          // "cage": FTF lines pass (in both views) and no fault is named, a
                             // weak note of a load modulated at the cage rate; "" otherwise
};

struct BearingDiagnosis {
  std::vector<Finding> findings;  // one per bearing with status kFault
  std::string channel;
  double band_centre_hz = 0;  // the demodulation band chosen from the kurtogram [Hz]
  double band_width_hz = 0;
  double band_level = 0;                      // its kurtogram level
  double band_kurtosis = 0;                   // its kurtosis (0 for Gaussian noise)
  std::vector<BearingStatus> bearings;        // in the order given
  std::vector<double> band_ses_frequency_hz;  // the band view's spectrum (step 3) the decisions
  std::vector<double> band_ses_amplitude;     // read, for plotting with their lines
};

// The fault's name in findings: "outer_race", "inner_race", "rolling_element", "cage" ("" for
// kNone).
const char* finding_name(BearingFault f);

// channel: validated (diag::validate), at least 2^(kurtogram_max_level + 7) samples, not constant;
// shaft_hz: the inner ring's rotation frequency [Hz], > 0; bearings: at least one, each within
// BearingSpec's ranges. The allowed bands must not be empty (a too-low sampling rate for the
// fault frequencies throws diag::InputError saying so).
BearingDiagnosis diagnose_bearings_from_signal(const diag::Signal& channel, double shaft_hz,
                                               std::span<const diag::BearingSpec> bearings,
                                               const BearingDiagnosisOptions& options = {});

// {"channel", "band": {"centre_hz", "bandwidth_hz", "level", "kurtosis"},
//  "findings": [{"bearing", "fault", "frequency_hz", "channel", "score_db", "evidence": {"family",
//  "basis", "harmonics_seen", "harmonics_scored", "line_db", "sideband_hz", "sidebands_seen",
//  "ftf_lines_seen", "other_view_score_db", "support_db", "support_null_db"}}],
//  "bearings": [{"bearing", "status", "fault", "note", "families": [{"fault", "fundamental_hz",
//  "score_db", "detected", "line_db", "sidebands_detected", "modulation_lines", "passes"}],
//  "whole_band_families": [...], "comb_support": {...} (when used)}]}
nlohmann::json to_json(const BearingDiagnosis& diagnosis);

}  // namespace detect
