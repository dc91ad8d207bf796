// Fault frequency bands, spectral metrics inside them, spectral-line measurement against the local
// floor, and a rolling-bearing fault decision from an envelope spectrum (MATLAB faultBands,
// bearingFaultBands and faultBandMetrics equivalents, plus the decision MATLAB leaves to the user).
//
// Spectra are given as two arrays of equal length: bin frequencies (strictly increasing, any
// spacing) and values (amplitude or power, >= 0). Nothing here computes a spectrum.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "detect/bearing/bearing_faults.hpp"
#include "diag/faults/fault_kind.hpp"

namespace detect {

struct SpectrumView {
  std::span<const double> frequency_hz;  // bin frequencies [Hz], strictly increasing, >= 3 bins
  std::span<const double> value;         // amplitude or power at each bin, >= 0, same length

  // Throws diag::InputError naming `where` and the array at fault. O(n).
  void validate(const std::string& where) const;
};

// ---- Bands --------------------------------------------------------------------------------------

struct FaultFrequency {
  std::string label;        // e.g. "BPFO"
  double frequency_hz = 0;  // fundamental [Hz], > 0
  double sideband_hz = 0;   // sideband spacing for this family [Hz], >= 0 (0: no sidebands), e.g.
                            // f_r around BPFI (a rotating inner-race defect is load-modulated
                            // once per turn), FTF around the ball-fault line
};

struct FaultBandOptions {
  int harmonics = 1;      // bands centred at h f0, h = 1..harmonics; 1..100
  int sidebands = 0;      // plus h f0 +- k f_sb, k = 1..sidebands, for families with f_sb > 0;
                          // 0..20
  double width_hz = 0;    // total width of every band [Hz], >= 0; 0: 10 % of the family's
                          // fundamental (so bands scale with each family)
  void validate() const;  // throws diag::InputError naming the field
};

struct FaultBand {
  std::string label;  // "2xBPFI-1xSB": harmonic, family label, sideband order
  int family = 0;     // index into the frequencies given
  int harmonic = 1;   // h
  int sideband = 0;   // k (signed; 0 = the harmonic itself)
  double centre_hz = 0;
  double low_hz = 0;   // centre - width/2, clipped at 0
  double high_hz = 0;  // centre + width/2
};

// Every band, family by family, harmonics ascending, sidebands -K..K within each harmonic; bands
// whose centre is <= 0 (a lower sideband below DC) are left out.
std::vector<FaultBand> fault_bands(std::span<const FaultFrequency> families,
                                   const FaultBandOptions& opt);

// The four bearing families in the order FTF, BPFO, BPFI, BALL (ball_fault_hz = 2 BSF), with
// sidebands at f_r around BPFI and at FTF around BALL when opt.sidebands > 0.
std::vector<FaultFrequency> bearing_fault_families(const BearingFrequencies& f);
std::vector<FaultBand> bearing_fault_bands(const BearingFrequencies& f,
                                           const FaultBandOptions& opt);

// ---- Metrics in bands ---------------------------------------------------------------------------

enum class SpectrumScale {
  kAmplitude,     // values are amplitudes: a bin's energy is value^2
  kPower,         // values are powers per bin (periodogram lines): energy is the value
  kPowerDensity,  // values are a PSD [unit^2/Hz]: energy is value x bin width (half the distance
                  // between the neighbouring bins; one full spacing at the ends)
};

struct BandMetrics {
  double peak_value = 0;         // largest value in the band (0 when the band holds no bin)
  double peak_frequency_hz = 0;  // its frequency (NaN when the band holds no bin)
  double energy = 0;             // sum of bin energies in [low_hz, high_hz]
  double energy_fraction = 0;    // energy / total energy of the whole spectrum
  int bins = 0;                  // bins inside the band
};

struct FaultBandMetrics {
  std::vector<BandMetrics> bands;  // one per band, in the order given
  double total_band_energy = 0;    // sum over bands (a bin in two overlapping bands counts twice,
                                   // as MATLAB's TotalBandPower does)
  double total_energy = 0;         // over every bin of the spectrum
};

FaultBandMetrics fault_band_metrics(const SpectrumView& spectrum, std::span<const FaultBand> bands,
                                    SpectrumScale scale = SpectrumScale::kAmplitude);

// ---- One spectral line against its local floor --------------------------------------------------

// The last-resort clip of a prominence: a floor of zero (an exactly noise-free spectrum with no
// precision floor given) reads as this, never as infinity.
inline constexpr double kMaxProminenceDb = 300.0;

// The dynamic range a measured spectrum is taken to carry by default [dB]. Why 120 dB: a line
// cannot be known to stand further above its floor than the measurement chain resolves, and an
// accelerometer chain resolves 100-120 dB (a 24-bit converter: 144 dB in theory, about 20
// effective bits = 120 dB in practice). A simulation carries less than its doubles suggest: the
// integrator's error is 1e-4..1e-3 of the RMS (60-80 dB) and FFT round-off ~1e-16 relative, so
// without this cap a noise-free record reads 230-300 dB "over the floor". Used through
// precision_floor() by the sideband and bearing decisions.
inline constexpr double kDefaultDynamicRangeDb = 120.0;

// The floor no measurement goes below: the spectrum's largest value divided by the dynamic range,
// max_k value_k 10^(-dynamic_range_db / 20). Every prominence measured against
// max(local floor, precision_floor) is then at most dynamic_range_db. `spectrum` is not
// re-validated. dynamic_range_db in (0, kMaxProminenceDb]; throws diag::InputError otherwise.
// O(bins).
double precision_floor(const SpectrumView& spectrum, double dynamic_range_db);

struct LineMeasurement {
  double expected_hz = 0;    // where the line was looked for
  double frequency_hz = 0;   // the largest bin within expected +- search half-width
  double amplitude = 0;      // its value
  double local_floor = 0;    // median of the floor window's bins (search window left out)
  double floor = 0;          // the floor measured against: max(local_floor, min_floor)
  double prominence_db = 0;  // 20 log10(amplitude / floor), in [-300, 300] (at most the dynamic
                             // range when min_floor = precision_floor(...)); 0 when !valid
  bool valid = false;        // false when the search window leaves the spectrum or the floor
                             // window holds fewer than 3 bins
};

// Measures the line near expected_hz in an amplitude spectrum against max(local median floor,
// min_floor). floor_halfwidth_hz must exceed search_halfwidth_hz >= 0; min_floor >= 0 (0: the
// local floor alone; a zero floor then reads kMaxProminenceDb). `spectrum` is not re-validated
// (validate() it once). O(bins in windows).
LineMeasurement measure_line(const SpectrumView& spectrum, double expected_hz,
                             double search_halfwidth_hz, double floor_halfwidth_hz,
                             double min_floor = 0);

// ---- Bearing fault decision from an envelope spectrum -------------------------------------------

enum class BearingFault { kNone, kCage, kOuterRace, kInnerRace, kRollingElement };
// The fault vocabulary's kind (diag/faults/fault_kind.hpp) and name: "none", "cage",
// "outer_race", "inner_race", "rolling_element".
diag::FaultKind fault_kind(BearingFault f);
const char* to_string(BearingFault f);

enum class BearingDecisionStatus {
  kNoFault,    // no fault family passes (a cage note may still be given)
  kFault,      // one family passes and beats every other passing family by margin_db
  kAmbiguous,  // two or more families pass within margin_db of each other, or the ball family
               // passes without the cage-rate modulation a ball fault carries: nothing named
};
// "no_fault", "fault", "ambiguous".
const char* to_string(BearingDecisionStatus s);

// Scoring (per family, fundamental f0 = FTF, BPFO, BPFI or 2 BSF): for h = 1..harmonics the line at
// h f0 is measured (measure_line) with a search half-width of max(search_bins bins,
// slip_fraction h f0) and a floor over floor_bins bins on each side beyond it, never below
// precision_floor(envelope, dynamic_range_db) (so every prominence and score is at most
// dynamic_range_db). A harmonic is
// detected when its prominence reaches line_threshold_db. The family's score is the sum of the
// detected harmonics' prominences divided by `harmonics` (undetected ones count 0) [dB].
// A family's lines pass when at least min_harmonics harmonics are detected and score >=
// score_threshold_db.
//
// Why these defaults: the bins of a noise-only (envelope) amplitude spectrum are close to Rayleigh
// distributed, median 1.18 sigma; one bin exceeds 10 dB over the median (3.72 sigma) with
// probability exp(-3.72^2 / 2) = 1e-3. A search window of w bins then detects noise with
// probability about w 1e-3 (w ~ 10: 1 %), and two detected harmonics of three with about
// 3 (w 1e-3)^2 = 3e-4. A defect comb that the eye sees in an envelope spectrum sits 15-30 dB over
// the floor. Report nothing rather than the wrong fault: a near tie is kAmbiguous.
//
// Which part the lines name (the physics of each class; Randall & Antoni 2011, sec. 2.1; Smith &
// Randall 2015, sec. 5):
//  - BPFO family: outer race. BPFI family: inner race (its shaft-rate sidebands are measured and
//    reported as evidence, not required: a defect in a load zone wider than the circle shows
//    none).
//  - 2 BSF family: a rolling element only when the cage-rate modulation a ball fault carries is
//    seen too: a sideband at +-FTF around a detected 2 BSF harmonic, or a detected FTF line. The
//    spalled ball goes in and out of the load zone with the cage, so its impacts are amplitude-
//    modulated at FTF (and a wandering spin axis drops whole passages, which adds to it). The
//    2 BSF lines without that modulation are not a ball's signature: kAmbiguous, nothing named.
//  - FTF family alone: a cage note (BearingDecision::cage_note), never a finding. FTF lines
//    are the modulation of a ball fault and appear with many disturbances of the load; a cage
//    fault has no impact family of its own to confirm it. The FTF family never competes with the
//    race and ball families.
//  - Lines of one family can fall on another's: a ball fault's spectrum holds m BSF + k FTF for
//    many k (the load zone and the track misses give the cage modulation many harmonics), and
//    BPFO = n FTF exactly, so a strong ball fault puts lines in the BPFI and BPFO windows; an
//    inner-race fault's m BPFI + k f_r fall on 2 BSF harmonics in turn. When two families pass,
//    the one whose own modulation is seen explains the other (FamilyScore::explained; the
//    explained family does not compete): the ball (>= 2 FTF sidebands and an FTF line) explains
//    an inner-race family with at most one shaft sideband (one may be a coincidence: for the
//    SKF 6205, 2 BPFI - f_r = 9.830 f_r and 2 (2 BSF) + FTF = 9.825 f_r share a bin), and
//    (>= 2 FTF sidebands and >= 2 FTF lines)
//    an outer-race family; the inner race (>= 2 shaft sidebands) explains a ball family with no
//    FTF sideband. Anything else within margin_db stays kAmbiguous.
struct BearingDecisionOptions {
  int harmonics = 3;              // harmonics per family, 1..20
  int min_harmonics = 2;          // detected harmonics needed to pass, 1..harmonics
  double slip_fraction = 0.01;    // relative search half-width (bearing slip 1-2 %), [0, 0.1]
  int search_bins = 2;            // minimal search half-width [bins], 0..50
  int floor_bins = 25;            // floor window beyond the search window, each side [bins], >= 3
  double line_threshold_db = 10;  // a harmonic is detected at this prominence [dB], > 0
  double score_threshold_db = 8;  // family score needed to pass [dB], > 0
  double margin_db = 6;           // winner's score over any other passing family's [dB], >= 0
  bool include_cage = true;       // score the FTF family too (needed for the ball's modulation
                                  // and the cage note)
  double sideband_threshold_db = 10;  // a sideband is seen at this prominence [dB], > 0; searched
                                      // within +-search_bins bins of (found line +- spacing)
  double dynamic_range_db = kDefaultDynamicRangeDb;  // floors no lower than the spectrum's
                                                     // largest value over this [dB],
                                                     // (line_threshold_db, 300]
  // Comb support (comb_support below), used to confirm in a second spectrum a family found in a
  // first one.
  int support_harmonics = 8;         // harmonics compared, 2..50
  int support_surrogates = 39;       // detuned combs forming the null, 9..500
  double support_max_detune = 0.15;  // surrogate fundamentals f0 (1 +- d), d spread evenly over
                                     // [support_max_detune / 5, support_max_detune], (0, 0.5]
  void validate() const;             // throws diag::InputError naming the field
};

struct FamilyScore {
  BearingFault fault = BearingFault::kNone;
  double fundamental_hz = 0;
  std::vector<LineMeasurement> lines;  // h = 1..harmonics
  int detected = 0;                    // lines at or above line_threshold_db
  double score_db = 0;
  bool lines_pass = false;                 // detected >= min_harmonics and score >= threshold
  double sideband_hz = 0;                  // spacing measured (f_r around BPFI, FTF around 2 BSF;
                                           // 0: none)
  std::vector<LineMeasurement> sidebands;  // per detected harmonic: lower, upper
  int sidebands_detected = 0;              // at or above sideband_threshold_db
  int modulation_lines = 0;  // 2 BSF only: detected FTF lines (the cage-rate modulation)
  bool passes = false;       // names its part: lines_pass, and for 2 BSF also the modulation
                             // (sidebands_detected + modulation_lines >= 1); never for FTF
  bool explained = false;    // passes, but another passing family's modulation explains its
                             // lines (see above): not a candidate
};

struct BearingDecision {
  BearingDecisionStatus status = BearingDecisionStatus::kNoFault;
  BearingFault fault = BearingFault::kNone;  // set only when status == kFault
  std::vector<FamilyScore> families;         // every scored family, in FTF, BPFO, BPFI, BALL order
  std::vector<BearingFault> candidates;      // the passing families (two or more when ambiguous)
  bool cage_note = false;  // the FTF family's lines pass and no fault is named: a weak note that
                           // the load is modulated at the cage rate, not a finding
  bool unmodulated_ball = false;  // the 2 BSF lines pass without FTF modulation (kAmbiguous)
};

// `envelope` is an amplitude envelope spectrum (the bearing's impacts show at the fault rate and
// its harmonics). Throws diag::InputError for a malformed spectrum or options.
BearingDecision diagnose_bearing_from_envelope(const SpectrumView& envelope,
                                               const BearingFrequencies& f,
                                               const BearingDecisionOptions& opt = {});

// The fundamental the detected lines of a family point to: sum of found frequencies over sum of
// harmonic numbers, over the detected lines (f0 nominal when none is detected).
double found_fundamental(const FamilyScore& family, double line_threshold_db);

// ---- Comb support: a family at a known fundamental, weak, in a second spectrum ------------------
//
// A family found in one spectrum (the kurtogram band's squared envelope, say) may sit only 3-7 dB
// over the floor in another (the whole band's), under the line threshold, though its lines are all
// there. A rank test decides whether they are: the comb statistic at f0 is the mean over
// h = 1..K of the prominences (each clipped to [-20, 20] dB so that one strong foreign line does
// not carry it) of the line at h f0, searched within +-(1 + h/4) bins (f0 known to a fraction of
// a bin from the first spectrum) against the local median floor. The same statistic at M detuned
// fundamentals f0 (1 +- d_m), none within the slip window, is its null, measured on the same
// spectrum (so shaft harmonics, the floor's shape and the bins' statistics are all in it). The
// family is supported when its statistic exceeds every surrogate's and is > 0 dB: by chance with
// probability 1 / (M + 1) (M = 39: 2.5 %). A surrogate comb that meets another real family only
// raises the null: the test errs toward no support.
struct CombSupport {
  double fundamental_hz = 0;
  int harmonics = 0;          // K used (harmonics above the spectrum's end are left out)
  double statistic_db = 0;    // at f0
  double null_max_db = 0;     // largest over the surrogates
  double null_median_db = 0;  // their median
  bool supported = false;
};
CombSupport comb_support(const SpectrumView& spectrum, double fundamental_hz,
                         const BearingDecisionOptions& opt = {});

}  // namespace detect
