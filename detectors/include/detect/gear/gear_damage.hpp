// Which shaft carries a damaged gear: time-synchronous averages per shaft from one tachometer
// (McFadden 1987; Stewart 1977's difference signal and FM4, Zakrajsek et al. 1993).
//
// Method.
//  1. Pulse times of one shaft's tacho (the input's when present, else the first tacho of a
//     known shaft), repaired (tacho.hpp), smoothed and corrected from a mesh line's phase on the
//     fastest shaft (pulse_refine.hpp, shared with analyze); every other shaft's revolutions by
//     scale_pulses() with the gearbox speed ratio.
//  2. For each shaft s that carries gears, the TSA of each of its channels (below) over s's
//     revolutions, and its difference signal d_s (tsa.hpp): TSA minus shaft order 1, minus every
//     mesh frequency of the gearbox that is an integer order of s (all its harmonics below the
//     Nyquist order) and their first-order sidebands. A mesh of another shaft pair that is
//     synchronous with s (in the three-shaft box the second mesh is order 9 of the input shaft) is
//     a tone in s's TSA and must go as well, else it dominates d_s.
//  3. The exclusive difference signal e_s: d_s without the orders that s shares with any faster
//     shaft f, i.e. without the multiples of p where f_f / f_s = p / q in lowest terms (q <= 64).
//     Why: with integer ratios a localised fault on a fast shaft is also periodic with every
//     slower shaft, so it appears in the slower shafts' TSAs as k = f_f / f_s equal impulses per
//     revolution (only at orders k, 2k, ...), and a fault on a slow shaft appears folded into the
//     faster shafts' TSAs (1/k of its amplitude, once per fast revolution). Removing the shared
//     orders makes e_s blind to faults on faster shafts; a fault on s keeps (k - 1)/k of its
//     energy in e_s (a single impulse minus its k-fold folded copy: still impulsive).
//  4. Significance: SNR_s = sum over the kept orders of |TSA_k|^2 over sum of var_k / N, var_k
//     the variance of order k over the N revolutions (the noise and every non-synchronous
//     component, which the average leaves at var_k / N). Noise alone: 1. When the speed varies
//     within the record (the reference's fitted revolution periods spread by more than 1 %: a
//     run-up), the average and var_k are weighted: each revolution by the inverse of its energy
//     in the kept orders, averaged over +-4 revolutions (inverse-variance weighting).
//  5. Score_s: the tooth that stands out. Real gears carry pitch errors on every tooth (ISO
//     1328: grade 6, f_pt ~ 8 um at m = 3 mm, several times the mesh deflection under load) and
//     runout. Physically these are a distributed pattern: every tooth meshes a little early or
//     late, so e_s holds a transient at EVERY tooth engagement with a random amplitude; each
//     transient is impulsive, so the kurtosis of e_s (FM4, Stewart 1977) is high on a healthy
//     gear (healthy shafts of a grade-6 box score FM4 6.8-9.3, above a bar of
//     5). A local fault (crack, chip, spall, missing tooth) is one or two teeth of one gear. So
//     the score compares each tooth with the other teeth of the same gear in the same
//     revolution-averaged signal: for each gear on s (z teeth, z >= 8), e_s less its orders below
//     z / 2 (a one-tooth event spans ~1.6 pitches, so its spectrum reaches far beyond z / 2,
//     while the cumulative pitch error's long wave and the runout lie below it), its local energy
//     L(theta) over one tooth pitch, and score = max L / median of L at the same place of the
//     other teeth (the two neighbours of the outstanding tooth left out). The largest over the
//     shaft's gears and channels. Only when SNR_s >= min_snr, else 1. Scale: noise alone and a
//     perfect gear give a few; random pitch errors (the largest of z chi-square-like tooth
//     energies over their median) up to ~15 in the tuning loop; a missing tooth hundreds.
//  6. Decision. A shaft is flagged when its score exceeds damaged_fm4 and "uncertain" above
//     healthy_fm4. The damaged shaft is the SLOWEST flagged shaft: a fault on s can flag faster
//     shafts (the folded copy) but never slower ones (step 3). When a faster flagged shaft's
//     period divides the chosen one's (a sub-harmonic ratio, e.g. the counter turning at half
//     the input speed), the finding's note says so; the result's note lists every such pair. No
//     flagged shaft: "healthy". When a shaft slower than the chosen one lies in the uncertain
//     band, the answer is "ambiguous" and both shafts are reported.
//
// Without a healthy baseline (options.baseline, gear_damage_baseline: the baseline's tooth pattern
// subtracted, so that pitch errors cancel), a small crack whose stiffness loss changes the
// transmission error less than the largest pitch deviation of the gear cannot be told from that
// deviation, and the locator stays silent (validation/gear_damage_loop.hpp reports where).
//  7. With a baseline, the recording is judged twice, alone and against the baseline, and the two
//     answers are fused. The comparison alone put 2 of 30 faults on a wrong shaft in the loop (a
//     fault on a fast pinion changes the dynamic load on a slower mesh, and with it that gear's
//     response to its own pitch errors, which the baseline taken without the fault does not
//     cancel; "the slowest flagged shaft" then names the slower one), while the recording alone
//     never named a wrong shaft there. So: both flag the same shaft, or only one of them flags
//     a shaft: that answer (the comparison's scores when it flags; the recording's own when only
//     it does, e.g. a baseline that already had the fault); they flag different shafts:
//     "ambiguous", both reported at half confidence, silence on which of the two; neither: healthy.
//     Each shaft carries both scores (score, score_alone).
//
// Channels per shaft: options.channels[shaft] when given; else the recording's signals whose
// location is a bearing of that shaft ("<shaft>_bearing1", the simulator's names, or a bearing of
// the gearbox description on that shaft) and direction along a line of action (one channel per
// mesh of the shaft); else every such bearing signal of the shaft; else every signal whose
// direction is along/normal to a line of action, horizontal or vertical (a single sensor on the
// casing serves all shafts); else, when no signal has such a direction (an imported
// measurement), every signal without a direction.
//
// CAUTION: the score answers "does one tooth stand out among the teeth of its gear", not "how
// large"; a fault spread over all teeth (uniform wear) does not raise it. Shafts with fewer than
// min_revolutions whole revolutions in the record are skipped and named in the result's note.
// Why the significance test: a shaft with nothing synchronous of its own has a tooth pattern of
// averaged noise, whose largest tooth over the median is a matter of chance.
#pragma once

#include <complex>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>
#include <vector>

#include "detect/angular/pulse_refine.hpp"
#include "detect/finding.hpp"
#include "detect/indicators/indicators.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/recording.hpp"

namespace detect {

// One channel's TSA of a shaft in a healthy recording: its spectrum (orders 0 .. spr / 2, the
// RealFft of the one-revolution average) and the noise variance of each order in the average.
struct BaselineTsa {
  std::vector<std::complex<double>> spectrum;
  std::vector<double> noise;
};
// A healthy baseline of the same gearbox (gear_damage_baseline): shaft -> channel -> TSA. Best
// taken at the same speed and load as the records it is compared with (the pattern of the
// pitch errors in the vibration depends on both).
struct GearDamageBaseline {
  std::map<std::string, std::map<std::string, BaselineTsa>> tsa;
};

struct GearDamageOptions {
  // TSA angular resolution [samples/rev], a power of two >= 64, the same for every shaft; 0
  // (default): per shaft, the smallest power of two >= 2.8 x the highest order analysed (below),
  // so that the resampling filter passes every order of the recorded band (its passband ends at
  // 0.72 x the Nyquist order, resample.hpp), at most 16384.
  int samples_per_rev = 0;
  int min_revolutions = 8;  // fewer whole revolutions of a shaft than this: the shaft is
                            // skipped (noted), >= 2
  // Degree of the least-squares polynomial fitted to the reference tacho's pulse times, which
  // replaces them (detect::smooth_pulse_times_polynomial, pulse_refine.hpp: why and how); 0: the
  // pulse times as detected (use it when the speed wanders within the record). [0, 8].
  int pulse_fit_degree = 3;
  // Pulse correction from the phase of a mesh line of the fastest shaft, once, before any shaft
  // is averaged (detect::refine_pulses, pulse_refine.hpp: why, how, and when a stage is
  // declined). Tests: gear_damage_test.cpp, TachoQuantisationIsCorrectedFromTheMeshLinePhase and
  // ASpeedErrorOfTheTachoIsRefinedFromTheMeshLines; pulse_refine_test.cpp.
  bool refine_speed = true;
  // Sidebands beyond the first also removed around every harmonic of the shaft's OWN gears' mesh
  // orders, >= 0 (other meshes synchronous with the shaft lose their first sidebands only).
  int extra_sideband_orders = 0;
  // Highest frequency analysed, as a fraction of the recording's Nyquist frequency fs / 2,
  // (0, 1]: the band an anti-aliasing filter leaves flat (the simulator's: 0.8). Orders up to
  // band_fraction x (fs / 2) / f_shaft.
  double band_fraction = 0.8;
  // Significance: the energy of the exclusive signal over the energy that noise alone would
  // leave in the TSA, estimated from the revolution-to-revolution scatter of each order (its
  // variance over the revolutions / N). Noise alone gives 1 +- about 1/sqrt(M), M the orders
  // kept (hundreds here); a shaft below min_snr has nothing synchronous of its own and is not
  // scored (score 3, Gaussian). >= 1.
  double min_snr = 2.0;
  // Level: the RMS of the exclusive signal's synchronous part (its energy less the expected
  // noise energy) over the RMS of the regular signal (shaft order 1, the mesh harmonics and
  // their first sidebands) of the same TSA, >= 0. A shaft below it is not scored. Why: at low
  // sensor noise, synchronous content far below what a tooth fault does to the mesh vibration
  // becomes significant (the simulator's residual integration error, about 5e-4 of the mesh
  // vibration; real gearboxes' small pitch errors) and its kurtosis is no evidence of damage.
  double min_level = 0.005;
  // A shaft that has faster shafts must also hold at least this share of its difference
  // signal's energy (in the band) in its exclusive orders, [0, 1). A fault on the shaft leaves
  // (k - 1)/k >= 1/2 of its impulse's energy there (k the ratio to the next faster shaft); a
  // large fault on a FASTER shaft reaches them only through a response that is not periodic
  // with that shaft (a nonlinear, period-doubled response to a missing tooth: contact loss),
  // well below 1 % of the energy in the simulated two-stage box, yet significant against noise.
  double min_exclusive_share = 0.2;
  // Thresholds on the score (step 5: the outstanding tooth's local energy over the median of
  // the other teeth'). The names are historical (the score was the noise-corrected kurtosis
  // FM4; analyze and its HTML report read them). Tuned on the gear-damage loop
  // (seed 11, the three-shaft and the 23/41 x 19/53 boxes, grades 5-8, runout 0-20 um): healthy
  // shafts scored up to 15, so damaged_fm4 = 20 raised no false alarm there; reported on other
  // seeds and gearboxes in docs/validation.md ("The damaged-shaft locator on realistic gears").
  double damaged_fm4 = 20.0;    // score above this: damaged, > healthy_fm4
  double healthy_fm4 = 12.0;    // score above this (and below damaged_fm4): uncertain, > 1
  std::string reference_shaft;  // shaft whose tacho gives the pulses; empty: the input shaft's
                                // tacho, else the first tacho whose location is a known shaft
  std::map<std::string, std::vector<std::string>> channels;  // shaft -> channels to use
                                                             // (overrides the automatic choice)
  // NA4-style comparison (Zakrajsek et al. 1993: NA4 normalises by a baseline; here the healthy
  // pattern itself is removed): when set, each shaft's TSA (per channel, when the baseline has
  // that shaft and channel at the same resolution) has the baseline's TSA subtracted in the
  // analysed band, after rotating it to the best match (the slower shafts' angle zero is where
  // the reference happened to be at the first pulse: it differs between records). The pitch
  // errors' and runout's pattern cancels; what is left is what changed: a fault, and noise (the
  // baseline's noise is added to the significance test's). The tooth score is then taken on
  // that difference. The SNR gate is then not applied: its noise, the revolution-to-revolution
  // scatter, counts the content that is not synchronous with the shaft (the other shafts'
  // patterns) as noise, which is right for one record (it averages out at that rate) but not
  // for the difference of two records of the same gears, where it largely cancels (in the loop
  // the difference's SNR fell to 0.05-0.3 with a fault present). The tooth score alone decides:
  // on a difference of noise alone it stays near 1-3. Null: no baseline.
  std::shared_ptr<const GearDamageBaseline> baseline;
  // Further healthy baselines of the same gears (other recordings of the same machine, e.g. a
  // history's reference; needs `baseline`): each shaft is compared with every one and the one
  // that explains it best, the lowest tooth score, is kept (its score, SNR, level, channel). The
  // gears' response to their own pitch errors moves with the operating point (a few percent of
  // torque or speed), so one healthy recording can differ from another in a tooth's place; a
  // healthy recording is explained by the reference recording nearest to its state, a damaged
  // tooth by none.
  std::vector<std::shared_ptr<const GearDamageBaseline>> more_baselines;

  void validate() const;  // throws diag::InputError naming the field
};

struct ShaftDamage {
  std::string shaft;
  double frequency_hz = 0;     // mean rotation frequency over the record [Hz]
  int revolutions = 0;         // whole revolutions averaged (0: skipped)
  int samples_per_rev = 0;     // TSA resolution used
  GearIndicators indicators;   // of the TSA and difference signal of `channel`, for the
                               // shaft's first gear as the monitored mesh (reporting only)
  std::string channel;         // the channel that gave the score
  std::string gear;            // the gear whose pitch window scored highest ("" when not
                               // scored); on a shaft of several gears not which one is damaged
                               // (the score favours the gear with more teeth): findings name
                               // them all
  double angle_deg = 0;        // where that tooth's event is in the shaft's revolution
  double score = 0;            // tooth score (step 5; 1: not scored; NaN: skipped)
  double fm4 = 0;              // FM4 of the exclusive signal as measured (noise included)
  double snr = 0;              // its energy over the expected noise energy (1: noise alone)
  double exclusive_share = 1;  // its energy over the difference signal's in the same band
  double level = 0;            // its synchronous RMS over the regular signal's RMS (options)
  bool compared = false;       // the healthy baseline was subtracted (options.baseline): the
                               // SNR gate is not applied (below) and level is the difference's
  double score_alone =
      std::numeric_limits<double>::quiet_NaN();  // with options.baseline: the
                                                 // tooth score of the recording alone (no
                                                 // baseline); NaN without
  bool significant = false;  // the gates pass: score compared with the thresholds
  bool damaged = false;      // snr >= min_snr, exclusive_share >= min_exclusive_share (when
                             // a faster shaft exists) and score > damaged_fm4
  bool uncertain = false;    // snr >= min_snr and healthy_fm4 < score <= damaged_fm4
  // Every gear on the shaft, in the description's order (those a finding names).
  std::vector<std::string> gears;
};

// The locator's findings (finding.hpp) are kind "gear_damage", fault tooth_damage: shaft, gears
// (every gear on the shaft: they share its revolution), channel (the one that gave the score),
// confidence = min(1, (score - healthy_fm4) / (2 (damaged_fm4 - healthy_fm4))), halved when
// ambiguous, note; evidence "score" (the shaft's tooth score), "snr", "exclusive_share" and
// "angle_deg" (ShaftDamage's).

struct GearDamageResult {
  std::vector<ShaftDamage> shafts;  // in gearbox order
  std::vector<Finding> findings;
  // "healthy": no shaft flagged; "damaged": one shaft; "ambiguous": two candidate shafts, both
  // reported (a slower shaft in the uncertain band below the flagged one).
  std::string status = "healthy";
  std::string reference_shaft;  // shaft whose tacho was used
  std::string note;             // skipped shafts, tacho repairs
};

// Throws diag::InputError for bad options, a recording without a usable tacho, a shaft named in
// options.channels that does not exist, or a missing channel.
GearDamageResult locate_gear_damage(const diag::Recording& rec, const diag::Gearbox& gb,
                                    const GearDamageOptions& options = {});

// The same with the reference shaft's once-per-revolution times given instead of read from a
// tacho channel (as detected: they are smoothed with options.pulse_fit_degree), e.g. from a
// tacho with several pulses per revolution reduced to one, or from a constant nominal speed
// (right only when the shaft turns at it: refine_speed corrects errors below half a period of a
// mesh line at the record's ends, not more). options.reference_shaft is not used. Throws
// diag::InputError as above, and for an unknown reference shaft or fewer than 3 pulses, or
// pulse times that are not finite and strictly increasing.
GearDamageResult locate_gear_damage(const diag::Recording& rec, const diag::Gearbox& gb,
                                    const std::string& reference_shaft,
                                    std::span<const double> pulse_times_s,
                                    const GearDamageOptions& options = {});

// The pulse correction's settings (pulse_refine.hpp) that locate_gear_damage uses: its fit degree,
// refine_speed, band, resolution, fewest revolutions and channels. analyze corrects its TSA's
// revolutions with the same.
PulseRefineOptions pulse_refine_options(const GearDamageOptions& options);

// The healthy baseline of a recording (GearDamageOptions::baseline): every shaft's TSA per
// channel, with the same pulse processing and resolution as locate_gear_damage (pass the same
// options). Throws diag::InputError as locate_gear_damage.
GearDamageBaseline gear_damage_baseline(const diag::Recording& healthy, const diag::Gearbox& gb,
                                        const GearDamageOptions& options = {});
GearDamageBaseline gear_damage_baseline(const diag::Recording& healthy, const diag::Gearbox& gb,
                                        const std::string& reference_shaft,
                                        std::span<const double> pulse_times_s,
                                        const GearDamageOptions& options = {});

// {"status", "reference_shaft", "note", "shafts": [...], "findings": [Finding's JSON
// (finding.hpp): "kind", "fault", "shaft", "gears", "channel", "confidence", "note", "evidence"
// and the evidence's "score", ...]}: the findings share their keys with `geardiag attribute`'s.
nlohmann::json to_json(const GearDamageResult& r);

}  // namespace detect
