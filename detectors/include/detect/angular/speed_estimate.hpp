// Shaft speed and angle from the vibration itself, without a tachometer (MATLAB rpmtrack's job,
// with a phase-demodulation stage for the accuracy time-synchronous averaging needs).
//
// The caller names candidate lines as ORDERS of a reference shaft (mesh harmonics h z ratio,
// shaft harmonics, bearing-family orders) and gives the nominal reference speed f_nom, known to
// within search_fraction. Three steps:
//
// 1. Choose the line. On the frame-averaged spectrum (the spectrogram's frames, i.e. a Welch PSD)
//    each candidate's band [o f_nom (1 - s), o f_nom (1 + s)] is searched and the candidate's
//    prominence is peak / median of the band widened by its width on each side (the median is
//    the local floor: a few lines, or a line smeared by a run-up, do not move it). Candidates above
//    0.8 x Nyquist are dropped. Candidates with the same order (to 1e-9) are one line (their labels
//    are joined). Candidates whose bands overlap cannot be told apart by one peak (a peak at F is
//    o_a at F/o_a or o_b at F/o_b): such a group is resolved only when two of its peaks stand in
//    the ratio of two of its orders (the stronger peak then names its order), else it is ambiguous
//    and left out. The most prominent line over every candidate and channel wins, unless no
//    other line of its channel confirms it (implies its speed to a frame bin) while some other
//    line is confirmed: the most prominent confirmed line then wins (a foreign line, e.g. an
//    electrical one, outshining a candidate in its band is passed over for the candidates that
//    agree with each other). Below min_prominence_db: no line.
// 2. Follow it (the ridge extraction of MATLAB's rpmtrack): from the frame where the
//    nominal speed holds, frame by frame forward and backward, the peak inside
//    +- max_step_fraction of the frequency predicted from the two previous frames (a bounded step
//    instead of rpmtrack's penalty), placed between bins by Gaussian (log-parabolic)
//    interpolation. Ridge speed = f_peak / order.
// 3. Refine by the line's phase (Bonnardot, Badaoui, Randall, Daniere, Guillet 2005, Mech. Syst.
//    Signal Process. 19(4), "Use of the acceleration signal of a gearbox in order to perform
//    angular resampling (with limited speed fluctuation)"): the channel is heterodyned by the
//    phase integrated from the ridge, z(t) = x(t) exp(-i phi_ref(t)), low-passed (zero-phase,
//    raised-cosine, passband demod_passband x the line's modulation frequency so that the
//    shaft-rate sidebands stay out), and the unwrapped phase psi(t) of the result corrects the
//    reference: theta(t) = phi_ref(t) + psi(t); done twice (the second pass removes the filter's
//    edge bias on the first pass's residual). The reference shaft's angle is
//      angle(t) = (theta(t) - theta(0)) / (2 pi order)   [rev],
//    uncertain by sigma_psi / (2 pi order) with sigma_psi ~ 1 / amplitude SNR in the demodulation
//    band: far better than a frame peak, and it holds through run-ups. The speed per frame is the
//    angle's increase over the frame / frame length (exact for constant acceleration); the mean
//    speed is the least-squares slope of angle vs time (the speed at mid-record for constant
//    acceleration).
//    CAUTION: a phase slip (the line's amplitude under the noise, so the phase can turn a whole
//    cycle unseen) shifts the angle by 1 / order rev from there on. The amplitude is checked
//    against the noise in the demodulation band and the record is kLowConfidence when the line
//    fades for more than max_fade_fraction of it.
//    CAUTION: the angle's zero is the record's first sample, not the shaft's keyway: the
//    revolution times are those of a tacho turned by an unknown constant angle (averages are
//    rotated, as with scale_pulses()).
// Limits: a sideband stronger than its carrier, or a foreign line stronger than the candidate in
// its band, is followed instead (the speed is then off by the sideband spacing; the other
// prominent candidates then contradict it, see SpeedEstimate::contradictions). The
// demodulation band is set by the lowest speed of the record, so over a wide run-up the ridge
// must stay within that band of the line at the top speed too (500 -> 3000 rpm in 6 s: ridge
// error <= 0.2 % of 1150 Hz against a 3.6 Hz band); a ridge further off loses the line there,
// which the fade check reports (kLowConfidence). A stop or a speed reversal is not followed.
// The angle read from a line carries the phase of the path from the source to the sensor at the
// line's frequency: constant on a steady machine (absorbed in the unknown zero), but in a run-up
// it drifts with speed (a delay tau: f_shaft tau rev; a resonance crossed: up to 1 / (2 order)
// rev; the simulated two-stage box 1000 -> 2000 rpm: 7.6e-3 rev). A nominal speed off by more
// than search_fraction can lock onto a neighbouring line of the same family (the two-stage box
// 10 % low: order 45 taken for 54): the other candidates then do not confirm it
// (confirmations == 0, said in the notes).
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace diag {
class Gearbox;
}

namespace detect {

// A candidate line, in orders of the reference shaft.
struct SpeedLine {
  double order = 0;  // cycles per revolution of the reference shaft, > 0
  std::string label;
  // Lowest modulation (sideband spacing) of the line, in orders of the reference shaft, > 0: for
  // a mesh line the speed ratio of the slower of its two shafts to the reference shaft; 1 for a
  // shaft harmonic. Sets the demodulation band (sidebands must stay out).
  double modulation_order = 1.0;
};

struct SpeedEstimateOptions {
  double search_fraction = 0.10;  // nominal speed uncertainty, relative, (0, 0.5)
  double frame_s = 0.2;           // STFT frame length [s], > 0, >= 16 samples, <= the record
  double hop_s = 0.05;            // STFT hop [s], (0, frame_s]
  int zero_padding = 4;  // STFT nfft / frame length (rounded up to a power of two), [1, 16]
  double min_prominence_db = 12;  // a line must stand this far over its floor, [3, 60]
  // Largest change of the line frequency from one frame to the next, relative to the predicted
  // frequency, (0, 0.5): the ridge's bounded step. Keep it below 1/order of the strongest
  // sideband (e.g. 1/z of a mesh line) when sidebands are strong.
  double max_step_fraction = 0.03;
  // Time [s] at which the nominal speed holds; < 0: over the whole record (a steady machine: the
  // line is chosen on the average of all frames, followed from the middle one); >= 0: at this
  // time (a run-up: chosen on the 3 frames around it, followed from there).
  double nominal_time_s = -1;
  double demod_passband = 0.4;         // demodulation passband edge / the line's lowest modulation
                                       // frequency (stopband edge twice it), (0, 0.5)
  double min_line_snr = 3;             // line amplitude / noise RMS in the demodulation band below
                                       // which the line has faded, > 0
  double max_fade_fraction = 0.01;     // faded share of the record above which the result is
                                       // kLowConfidence, [0, 1]
  double stationary_tolerance = 0.01;  // (max - min) / mean speed below which the machine is
                                       // steady, > 0
  int points_per_rev = 100;            // angle samples kept per revolution at the top speed,
                                       // >= 8 (linear interpolation between them)
  // A caller that uses only confirmed lines (SpeedEstimate::confirmations > 0) sets this: a line
  // no other candidate confirms then ends the estimate after step 1 (kUnconfirmed), without the
  // ridge and the demodulation it would not use (most of the cost).
  bool require_confirmation = false;

  void validate() const;  // throws diag::InputError naming the field
};

enum class SpeedStatus {
  kTracked,        // a line was followed and its amplitude stayed above the noise
  kLowConfidence,  // followed, but the line faded under the noise for more than
                   // max_fade_fraction of the record: the angle may have slipped by 1/order rev
  kNoLine,         // no candidate stands min_prominence_db over its band: no speed claimed
  kAmbiguous,      // prominent lines only in groups of overlapping candidates that cannot be
                   // told apart: no speed claimed
  kUnconfirmed,    // require_confirmation and no other candidate confirms the chosen line: not
                   // followed, no speed claimed (line, frequency, prominence, contradictions set)
  kElsewhere,      // the candidate lines, all together, fit a speed outside the search band
                   // (better_speed_hz) clearly better than what was found inside it: no speed
                   // claimed; search again around better_speed_hz
};
std::string_view to_string(SpeedStatus s);

struct SpeedEstimate {
  SpeedStatus status = SpeedStatus::kNoLine;
  // The line followed (valid for kTracked and kLowConfidence).
  SpeedLine line;
  double line_frequency_hz = 0;  // its peak on the averaged spectrum (steady) or at
                                 // nominal_time_s (run-up) [Hz]
  double prominence_db = 0;      // its peak over the floor [dB]
  std::size_t channel = 0;       // index of the channel it was followed on
  // Other prominent candidates on that channel whose peaks imply the same speed to a frame bin
  // (confirmations) or not (contradictions: a sideband or a foreign line may have been taken for
  // a candidate; the notes name them). Orders equal to the chosen one are not counted.
  int confirmations = 0;
  int contradictions = 0;
  // The harmonic-set check (steady records): how many of the candidate lines (distinct orders
  // below 0.8 x Nyquist) stand min_prominence_db over their neighbourhood, at the speed found in
  // the band (lines_found of lines_counted; 0 of 0 when none was found) and at the speed in
  // [nominal / 2, 2 x nominal] that shows them most strongly (better_*: the largest sum of the
  // found lines' prominences, each at most 60 dB, on the channel where it is largest);
  // kElsewhere when that speed is outside the band, shows more lines (at least 3, at least half
  // of its own) and a larger sum than the band's speed. The candidates are taken with their
  // doubles (orders x 1 and x 2), and a speed whose half (third) has lines of its own (a third
  // of the lines it predicts that the speed does not) is that half (third): an octave error.
  int lines_found = 0;
  int lines_counted = 0;
  double better_speed_hz = 0;
  int better_lines_found = 0;
  int better_lines_counted = 0;
  // Per STFT frame: centre time [s], speed of the reference shaft from the angle [Hz] and from the
  // frame's spectral peak alone (the ridge) [Hz].
  std::vector<double> time_s;
  std::vector<double> speed_hz;
  std::vector<double> ridge_speed_hz;
  double mean_speed_hz = 0;  // least-squares slope of the angle over the record [rev/s]
  double min_speed_hz = 0;   // over the frames
  double max_speed_hz = 0;
  bool stationary = false;    // (max - min) / mean <= stationary_tolerance
  double faded_fraction = 0;  // share of the record where the line was under min_line_snr
  // The demodulated line's phase jitter [deg]: sigma_psi = n / (sqrt(2) a), the noise n in the
  // demodulation band against the line's median amplitude a there (one quadrature of the noise
  // turns the phase); the reference shaft's angle is uncertain by it / order.
  double phase_jitter_deg = 0;
  // Reference-shaft angle [rev], 0 at the first sample: angle_rev[j] at t = j * angle_step_s.
  double angle_step_s = 0;
  std::vector<double> angle_rev;
  std::vector<std::string> notes;  // the choice, candidates dropped and why, fades

  bool has_speed() const {
    return status == SpeedStatus::kTracked || status == SpeedStatus::kLowConfidence;
  }
  // Angle at t_s [rev], linear between the kept samples, clamped to the record. Requires
  // has_speed().
  double angle_rev_at(double t_s) const;
};

// channels: one or more records of the same length and rate (e.g. the accelerometers of one
// machine); nominal_speed_hz: the reference shaft's nominal speed [Hz], > 0; lines: the
// candidates. Throws diag::InputError for bad options, fs_hz <= 0, no channel, channels of
// different lengths, non-finite samples, a record shorter than one frame, no candidate or a bad
// candidate. No line found is an outcome (status), not an error.
SpeedEstimate estimate_speed(const std::vector<std::span<const double>>& channels, double fs_hz,
                             double nominal_speed_hz, const std::vector<SpeedLine>& lines,
                             const SpeedEstimateOptions& options = {});
SpeedEstimate estimate_speed(std::span<const double> x, double fs_hz, double nominal_speed_hz,
                             const std::vector<SpeedLine>& lines,
                             const SpeedEstimateOptions& options = {});

// Candidate lines of a gearbox in orders of shaft `reference_shaft` (an index into
// gb.shafts()): harmonics h = 1 .. harmonics of every mesh (order h z_driver |r_driver| / |r_ref|
// with r the shafts' speed ratios; modulation order: the slower of the mesh's two shafts), equal
// orders of different meshes kept once by estimate_speed(); for a gearbox without meshes, the
// shaft harmonics 1 .. harmonics of every shaft (modulation order 1 / the highest harmonic,
// to keep the band narrow). Throws diag::InputError for a bad shaft index or harmonics < 1.
std::vector<SpeedLine> gearbox_speed_lines(const diag::Gearbox& gb, int reference_shaft,
                                           int harmonics = 3);

// Once-per-revolution times [s] of the reference shaft: where the angle reaches
// first_angle_rev + k, k = 0, 1, ..., inside the record (linear between the kept angle samples).
// Pass them to tsa(), resample_by_angle() or scale_pulses() as tacho pulses (pulses_per_rev 1).
// Throws diag::InputError when the estimate holds no speed (status kNoLine or kAmbiguous).
std::vector<double> revolution_times_s(const SpeedEstimate& estimate, double first_angle_rev = 0);

}  // namespace detect
