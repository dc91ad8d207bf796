// Offline analysis of a whole recording (`geardiag analyze`): every detector of the library run
// on every channel, tied to the gearbox description when there is one, collected into one result
// that the report library (report/report.hpp) prints, serialises to JSON and renders to HTML.
//
// Per channel (tacho and angle channels get the time-domain indicators only):
//  - time-domain indicators: RMS, peak, crest factor, kurtosis, skewness (indicators.hpp);
//  - amplitude spectrum of the whole record (spectrum.hpp, Hann, peak scaling; the DFT zero-padded
//    to next_fast_length(n), fft.hpp: a record of n samples with a large prime factor, like
//    CWRU's 121265 = 5 x 79 x 307, transforms 10x faster at 121500; every sample is kept, the
//    window and its resolution are the record's, the bins are fs / nfft apart, under 1 % closer
//    than fs / n above 10^4 samples) and Welch PSD (welch.hpp); the largest spectral peaks;
//  - envelope spectrum demodulated in the band the fast kurtogram selects (kurtogram.hpp,
//    envelope.hpp; Randall & Antoni 2011, sec. 3.3).
// With a gearbox:
//  - shaft speeds from a tachometer when the recording has one (tacho.hpp: pulses of the shaft
//    named by the tacho's location or name, repaired; the other shafts by the gearbox ratios),
//    otherwise the description's nominal input speed;
//  - mesh frequencies, the amplitude at h f_mesh, and the sideband family of each mesh with the
//    mesh's two shafts as candidates (sidebands.hpp: which shaft the sidebands point at);
//  - order spectrum in input-shaft orders (order_spectrum.hpp) and, per shaft, the TSA with its
//    regular, residual and difference signals and the gear metrics FM0, FM4, M6A, M8A, NA4, ER,
//    SER, SLF, SI of each gear on the shaft (tsa.hpp, indicators.hpp). Without a tacho the angle
//    comes from the vibration (speed_estimate.hpp: a steady record first, else a run-up followed
//    from the time where the nominal speed holds, nominal_time_s, default mid-record), else from
//    the constant nominal speed; the result says which was used (AnalysisSpeed::source);
//  - at varying speed (AnalysisSpeed::stationary false) the order domain: the amplitude
//    spectrum, Welch PSD, sidebands, two-direction energies, envelope spectrum and bearing
//    diagnosis of each channel run on the channel resampled at uniform input-shaft angles
//    (resample.hpp) and read as a record at the mean speed, so a line of order q stands at
//    q x the mean speed however the speed moved (the envelope is demodulated in time, in the
//    kurtogram's band, and then resampled: the envelope order spectrum); every frequency of
//    such a channel is "at the mean speed" (AnalysisSpeed::spectra_domain == "order");
//  - every bearing of the description, on the sensor channels at that bearing (location ==
//    bearing name; every sensor channel when none is): fault frequencies, fault bands and band
//    metrics on the channel's envelope spectrum (bearing_faults.hpp, fault_bands.hpp), and the
//    decision of diagnose_bearings_from_signal (bearing_diagnosis.hpp: cepstral prewhitening, a
//    guarded kurtogram band and the whole band must name the same fault; validated on CWRU);
//  - the two-direction comparison (two_direction.hpp): for each location with an along_loa and a
//    normal_loa channel, the mesh-harmonic energies in both and their normal-to-along ratio [dB];
//  - which shaft carries a damaged gear (gear_damage.hpp: TSA per shaft, the noise-corrected
//    kurtosis of the orders no faster shaft shares; validated in the closed loop with the
//    simulator), from the shaft angles above: the tacho's, else the nominal speed (a speed off
//    the nominal smears the averages: no finding rather than a wrong one).
// Findings (Finding, finding.hpp: the one finding type of every module; here the locator's, the
// bearing vote's (evidence channels_pointing, channels_analysed, score_db) and, with a baseline,
// the wear indicator's; the sideband vote is reported as a note, never as a finding: healthy
// gears with ordinary pitch errors pass it on every recording, docs/validation.md, "The sideband
// vote is not a finding");
// faults in the one vocabulary of diag/faults/fault_kind.hpp) summarise what points at a shaft,
// gear or bearing, each with a confidence and a note; only sensor channels (sensor_channels below)
// vote. The code is in stages (detectors/src/analysis/stages.hpp lists them: a table of
// recording-level stages and a table of per-channel stages, each row a name, what it needs and
// one function; kinematics, angle plans, per-channel spectra / envelope and bearings / sidebands
// / TSA, two directions, findings). Steps that cannot run on this record (too few revolutions for
// a TSA, a record too short for the kurtogram) are skipped with a note, not an error: they are
// outcomes.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "detect/angular/tsa.hpp"
#include "detect/baseline/baseline.hpp"
#include "detect/bearing/bearing_diagnosis.hpp"
#include "detect/bearing/bearing_faults.hpp"
#include "detect/finding.hpp"
#include "detect/gear/fault_bands.hpp"
#include "detect/gear/gear_damage.hpp"
#include "detect/gear/sidebands.hpp"
#include "detect/gear/two_direction.hpp"
#include "detect/indicators/indicators.hpp"
#include "detect/spectral/kurtogram.hpp"
#include "detect/spectral/window.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/channels.hpp"
#include "diag/io/recording.hpp"

namespace detect {

struct AnalyzeOptions {
  WindowType spectrum_window = WindowType::kHann;  // amplitude spectrum window (Hann: 1.5-bin
                                                   // ENBW, resolves sidebands one shaft apart)
  std::size_t welch_nperseg = 4096;  // Welch segment [samples], [8, 2^24]; shortened to the
                                     // largest power of two that fits a short record
  int kurtogram_max_level = 6;       // [1, 12]; lowered to log2(N) - 7 for short records
  int tacho_pulses_per_rev = 0;      // pulses per revolution of every tacho channel, [0, 1e5];
                                     // 0: each tacho's own (Signal::ppr)
  int tsa_min_revolutions = 10;      // fewer whole revolutions: the shaft's TSA is skipped, >= 2
  int peaks_reported = 8;            // largest spectral / envelope peaks listed per channel, 0..100
  int threads = 0;                   // channels analysed in parallel, [0, 256]; 0: one per
                                     // hardware thread. The result does not depend on it.
  int plot_points = 1500;            // points kept per stored trace (peak-hold decimation), >= 16
  double envelope_plot_max_hz = 0;   // envelope trace kept up to here [Hz], >= 0; 0: 5 x the
                                     // highest bearing fault line, else 1 kHz (capped at fs/2)
  SidebandOptions sidebands;         // mesh harmonics and sideband orders examined per mesh
  GearMetricOptions gear_metrics;    // mesh_harmonics and ser_sidebands used for every gear
                                     // (mesh_order is set per gear; the others are lowered when
                                     // they do not fit the TSA's Nyquist order)
  FaultBandOptions fault_bands{3, 0, 0.0};  // bearing bands: harmonics 1..3, no sidebands
  BearingDiagnosisOptions bearing;          // bearing diagnosis per channel (its kurtogram
                                            // level is lowered to log2(N) - 7 for short records)
  TwoDirectionOptions two_direction;        // mesh harmonics summed in the two-direction ratio
  GearDamageOptions gear_damage;            // the damaged-shaft locator (reference_shaft is
                                            // not used: the shaft angles are analyze's own)
  // Called with the name of each stage as it starts ("kinematics", "angle_plans", "channels",
  // "two_direction", "gear_damage", "findings";
  // kinematics, two_direction, gear_damage and findings with a gearbox only); the CLI draws a
  // progress line on a terminal.
  std::function<void(const std::string&)> progress;
  // Fill the curves only a plot draws: ChannelAnalysis::spectrum, psd, order_spectrum and
  // spectrogram, MeshAnalysis::zoom (and, where the envelope and bearing stages honour it,
  // envelope, waveform, kurtogram, BearingAnalysis::decision_envelope). false (the CLI without
  // --html or --curves): they stay empty and what only they need is not computed (the Welch
  // PSD, the spectrogram, the order spectrum: psd_resolution_hz and psd_segments are then set
  // from the Welch layout, WelchOptions::segments); every other field, the findings and the
  // notes are the same.
  bool traces = true;
  // Keep each vibration channel's whole amplitude and envelope spectra as power (ChannelAnalysis::
  // spectrum_power, envelope_power), for a caller that averages them over the frames of a log.
  bool keep_spectra = false;
  bool timing = false;               // record the wall time of each stage (AnalysisResult::
                                     // timing_s); off by default: it differs run to run
  bool speed_from_vibration = true;  // without a tacho, estimate the speed from the strongest
                                     // mesh line within +-10 % of the nominal (speed_estimate.hpp)
  double nominal_time_s = -1;        // when the nominal speed holds [s], for the speed from the
                                     // vibration; < 0: a steady record first, else (no steady line:
                                     // a run-up) mid-record

  void validate() const;  // throws diag::InputError "analyze: <field>: ..."
};

// A curve kept for plotting: at most plot_points (x, y) pairs, peak-hold decimated.
struct PlotTrace {
  std::vector<double> x, y;
};

struct SpectralPeak {
  double frequency_hz = 0;
  double amplitude = 0;  // channel units (peak scaling)
};

struct TimeIndicators {
  double rms = 0, peak = 0, crest_factor = 0, kurtosis = 0, skewness = 0;  // kurtosis: 3 Gaussian
};

struct MeshAnalysis {
  int mesh = -1;     // index into the gearbox's meshes
  std::string name;  // "<driver>_<driven>"
  double mesh_hz = 0;
  SidebandAnalysis sidebands;  // mesh harmonics (LineMeasurement) and candidate shafts' families
  PlotTrace zoom;              // full-resolution spectrum around the fundamental +- (K + 2) f_shaft
};

struct GearMetricsRow {
  std::string gear;
  int teeth = 0;
  GearIndicators indicators;  // NA4 against this record alone (an ensemble of one)
};

struct ShaftTsaAnalysis {
  std::string shaft;
  bool computed = false;  // false: skipped, see note
  std::string note;
  int revolutions = 0;
  int samples_per_rev = 0;
  std::vector<double> tsa, regular, residual, difference;  // one revolution each
  std::vector<GearMetricsRow> gears;
};

// A spectrogram kept for the report: the STFT power in dB on a bounded grid (the record cut into
// at most kSpectrogramColumns spans of equal length, each span the mean of its Welch segments'
// PSD, Hann, 50 % overlap; frequency bins of nperseg = 2 x kSpectrogramRows samples up to fs/2),
// so a long file gives a spectrogram of the same size as a short one.
struct SpectrogramTrace {
  std::vector<double> time_s;        // span centres [s]
  std::vector<double> frequency_hz;  // bin frequencies [Hz]
  std::vector<double> psd_db;        // row-major [time][frequency]: 10 log10(PSD / 1 unit^2/Hz)
                                     // [dB], floored at 200 dB below the largest value
};
inline constexpr std::size_t kSpectrogramColumns = 240;
inline constexpr std::size_t kSpectrogramRows = 128;

// One harmonic of a bearing fault family as the decision measured it on its envelope spectrum.
struct BearingLine {
  std::string label;         // "BPFO", "2xBPFI", "FTF", "3x2BSF"
  int family = 0;            // 0 FTF, 1 BPFO, 2 BPFI, 3 ball (2 BSF): FaultBand::family's order
  int harmonic = 1;          // h
  double expected_hz = 0;    // h f0 (nominal)
  double found_hz = 0;       // the largest bin of the search window
  double prominence_db = 0;  // over the local floor
  bool seen = false;         // detected by the decision (prominence >= its line threshold)
};

struct BearingAnalysis {
  std::string bearing, shaft;
  BearingFrequencies frequencies;
  std::vector<FaultBand> bands;
  FaultBandMetrics metrics;  // on the channel's envelope spectrum (amplitude scale; the plotted
                             // one: kurtogram band of the raw signal)
  bool diagnosed =
      false;  // false: diagnose_bearings_from_signal could not run, the channel's notes say why
  BearingStatus diagnosis;  // diagnose_bearings_from_signal on this channel: the combined status
                            // and fault, the decisions on the band-selected and the whole-band SES
  double band_centre_hz = 0, band_width_hz = 0;  // its demodulation band (prewhitened signal)
  PlotTrace decision_envelope;     // the decision's own spectrum (band view: squared envelope of
                                   // the prewhitened signal in that band), up to 1.1 x the
                                   // highest harmonic scored; empty when not diagnosed
  std::vector<BearingLine> lines;  // every harmonic the band view scored (diagnosed only)
};

// One channel's analysis, under the channel's identity (name, rate, unit, direction, location,
// role, shaft, mesh: the signal's own).
struct ChannelAnalysis : diag::ChannelIdentity {
  std::size_t samples = 0;
  bool vibration = true;  // spectra computed: vibration, force and displacement roles; false
                          // for angles, speeds and other quantities (only `time` is filled)
  bool sensor = true;     // in sensor_channels(): votes in the findings (false: shown only)
  TimeIndicators time;
  double spectrum_resolution_hz = 0;  // bin spacing fs / nfft (nfft = next_fast_length(samples))
  double spectrum_enbw_hz = 0;
  std::vector<SpectralPeak> spectrum_peaks;  // largest local maxima, descending amplitude
  // Parts of a long log whose spectra are averaged into spectrum_peaks and spectrum (their power
  // per bin; 1: this record's), and into envelope_peaks and envelope.
  std::size_t spectrum_parts = 1, envelope_parts = 1;
  // With AnalyzeOptions::keep_spectra: the squares of the amplitude spectrum the peaks come from
  // (bins spectrum_resolution_hz apart) and of the envelope spectrum up to where its peaks are
  // sought (bins envelope_resolution_hz apart); single precision: a frame's spectra for averaging.
  std::vector<float> spectrum_power, envelope_power;
  double envelope_resolution_hz = 0;
  PlotTrace spectrum;  // amplitude spectrum [unit] vs Hz
  PlotTrace psd;       // Welch PSD [unit^2/Hz] vs Hz
  double psd_resolution_hz = 0;
  std::size_t psd_segments = 0;
  double envelope_low_hz = 0, envelope_high_hz = 0;                   // demodulation band
  double kurtogram_level = std::numeric_limits<double>::quiet_NaN();  // NaN: not run
  double kurtogram_kurtosis = std::numeric_limits<double>::quiet_NaN();
  std::vector<SpectralPeak> envelope_peaks;
  PlotTrace envelope;                 // envelope spectrum [unit] vs Hz
  std::vector<MeshAnalysis> meshes;   // one per gearbox mesh
  PlotTrace order_spectrum;           // amplitude vs input-shaft order (empty when not computed)
  std::vector<ShaftTsaAnalysis> tsa;  // one per shaft with gears
  std::vector<BearingAnalysis> bearings;
  std::vector<std::string> notes;  // steps skipped on this channel and why
  PlotTrace waveform;  // the record as sampled [unit] vs time [s] (min/max decimated), for the
                       // report's time waveform; filled with the envelope (vibration channels)
  std::vector<KurtogramLevel> kurtogram;  // the fast kurtogram's map the envelope band came
                                          // from (empty: not run); the report draws it
  SpectrogramTrace spectrogram;           // of the record in time (empty: too short)
};

struct TwoDirectionRow {
  std::string location, along_channel, normal_channel, mesh;
  TwoDirectionComparison comparison;
};

struct AnalysisShaftSpeed {
  std::string shaft;
  double speed_hz = 0;
  std::string source;  // "tacho", "tacho <shaft> x ratio", "nominal"
  int tacho_repairs = 0;
};

// The reference shaft's speed over the record and where it came from (analyze's kinematics).
struct AnalysisSpeed {
  std::string source;           // "tacho", "vibration" (speed_estimate.hpp) or "nominal"
  std::string reference_shaft;  // the shaft measured or estimated
  std::string line;             // the tacho or the vibration line followed
  double nominal_rpm = 0;       // the description's (or --rpm's, or the file's) speed
  double mean_rpm = 0, min_rpm = 0, max_rpm = 0;
  bool stationary = true;                 // max - min within 1 % of the mean
  std::vector<double> time_s, speed_rpm;  // the speed over time (empty: nominal)
  // From the vibration: the followed line's phase jitter [deg] and the reference shaft's angle
  // uncertainty it gives [deg of the shaft] (SpeedEstimate::phase_jitter_deg; NaN otherwise).
  double phase_jitter_deg = std::numeric_limits<double>::quiet_NaN();
  double angle_uncertainty_deg = std::numeric_limits<double>::quiet_NaN();
  // "time": spectra of the record as sampled (a steady speed); "order": at varying speed, the
  // spectra, sidebands and envelope spectra are order spectra of the input shaft, their
  // frequencies stated at the mean speed (order x mean speed); empty without a gearbox.
  std::string spectra_domain;
};

struct AnalysisMesh {
  std::string name, driver, driven;
  double frequency_hz = 0;
};

// Comparison with healthy baseline recordings (score_against_baseline below). Rendered in the
// report and the JSON ("anomaly_score", "alarm", "anomaly_threshold", "baseline_deviations",
// "baseline").
struct AnalysisBaselineDeviation {
  std::string feature;  // "<channel>.<feature>" (baseline.hpp's names, e.g. "a1.kurtosis_log")
  double value = 0;     // the recording's feature value
  double baseline_centre = 0;  // median over the baseline samples
  double baseline_spread = 0;  // max(1.4826 MAD, spread_floor): a robust standard deviation
  double z = 0;                // (value - centre) / spread [robust sigmas]
};
// The wear indicator of one mesh against the baseline (wear_against_baseline below).
struct AnalysisMeshWear {
  std::string mesh;                      // diag::mesh_name
  double mesh_hz = 0;                    // at the recording's speed (the analysis's kinematics)
  std::vector<double> baseline_mesh_hz;  // at each baseline recording's speed, in order
  double growth_db = 0;                  // mesh_harmonic_growth.hpp: mean over the channels
  double threshold_db = 0;               // flagged above it
  bool flagged = false;
  std::vector<std::string> channels;  // the channels compared
  std::vector<double> channel_db;     // growth per channel [dB], same order
};
struct AnalysisBaseline {
  double anomaly_score = 0;  // mean of z^2 over every feature (baseline.hpp)
  double threshold = 0;      // alarm when anomaly_score > threshold
  bool alarm = false;
  std::vector<AnalysisBaselineDeviation> deviations;  // every feature, largest |z| first
  std::vector<std::string> channels;    // channels compared (in the recording and every baseline)
  std::vector<std::string> recordings;  // the baseline recordings' names, in the order given
  std::size_t samples = 0;              // baseline feature sets fitted (recordings x segments)
  std::vector<std::string> notes;       // channels left out and why, segment counts lowered
  std::vector<AnalysisMeshWear> wear;   // per mesh (wear_against_baseline); empty without one
};

// One frame of a whole-log analysis (analyze_file, which analyses a long recording frame by
// frame): a stretch [start_s, end_s) of the recording analysed on its own.
struct AnalysisSegment {
  double start_s = 0, end_s = 0;
  std::string verdict;  // "finding", "no finding" or "not examined"
  std::string reason;   // why not examined (empty otherwise)
  // Why the segment starts inside a frame: the operating state changed there (a speed step, a
  // tacho splice); empty where it starts at a frame's start.
  std::string cut;
  // The reference shaft's mean speed in the frame and where it came from (AnalysisSpeed); NaN
  // and empty without a gearbox or when not examined.
  double speed_rpm = std::numeric_limits<double>::quiet_NaN();
  std::string speed_source;
  std::vector<std::size_t> findings;  // indices into AnalysisResult::findings seen in the frame
  std::vector<std::string> channels;  // the sensor channels, in the order of `indicators`
  std::vector<TimeIndicators> indicators;
  // The anomaly score against the baseline recordings (NaN: no baseline).
  double anomaly_score = std::numeric_limits<double>::quiet_NaN();
};

// What of a recording was examined (analyze_file).
struct AnalysisCoverage {
  double duration_s = 0;  // the recording's (its longest channel)
  double analysed_s = 0;  // the frames analysed, summed
  double frame_s = 0;     // the frames' length (the last ones may differ by a sample)
  std::size_t frames = 0, frames_examined = 0;
  std::size_t detail_frame = 0;  // the frame whose channels the result details (spectra, TSA)
  // Why a part was not examined: a limit asked for (--max-samples) or the frames' reasons.
  std::vector<std::string> not_examined;
  // Every sample of the recording was analysed.
  bool complete() const { return not_examined.empty() && frames_examined == frames; }
};

// One stage of the analysis table (the recording's stages, then the channels'), in the order run:
// on how many of its units it ran (1 for a recording-level stage; channels for a channel stage)
// and on how many not, and why not (what it needs that they lack). A stage that ran may still
// have found nothing to do (too few revolutions for a TSA): the channel's notes say so.
struct StageRun {
  std::string stage;
  std::size_t ran = 0, skipped = 0;
  std::string why;  // empty when nothing was skipped
};

struct AnalysisResult {
  std::string gearbox_name;  // empty without a gearbox
  std::string input_shaft;   // the gearbox's input shaft (order spectra are in its orders)
  double duration_s = 0;
  std::vector<AnalysisShaftSpeed> shafts;
  AnalysisSpeed speed;
  std::vector<AnalysisMesh> meshes;
  std::vector<ChannelAnalysis> channels;
  std::vector<TwoDirectionRow> two_direction;
  std::vector<Finding> findings;  // every finding, most confident first
  std::optional<AnalysisBaseline> baseline;
  std::optional<GearDamageResult> gear_damage;  // the locator's result (absent: not run, notes
                                                // say why)
  std::string gear_damage_angles;  // "tacho", "vibration" or "nominal": the shaft angles used
  std::vector<std::string> notes;  // recording-level notes (speed source, skipped steps)
  std::vector<StageRun> stages;    // what ran and what did not, and why
  std::map<std::string, double> timing_s;  // wall time per stage [s] (AnalyzeOptions::timing),
                                           // and "channel_cpu.<stage>": the CPU time of each
                                           // per-channel stage summed over the channels
  // A whole-log analysis (analyze_file): the frames and what was examined; empty and absent when
  // analyze_recording ran on one record.
  std::vector<AnalysisSegment> segments;
  std::optional<AnalysisCoverage> coverage;
};

// Throws diag::InputError for bad options, a recording without signals, or a signal that fails
// diag::validate. `gb` may be null: then only the unit-free indicators and spectra are computed.
AnalysisResult analyze_recording(const diag::Recording& rec, const diag::Gearbox* gb,
                                 const AnalyzeOptions& opt = {});

// The channels that stand for the machine's vibration (role vibration): the channel contract's
// (diag/io/channels.hpp). Only they vote in findings and enter a baseline.
using diag::sensor_channels;

// ---- Baseline comparison (detect/baseline/baseline.hpp) ----
// Each baseline recording is cut into `segments_per_recording` equal parts and each part gives one
// baseline sample: the features of baseline_features() of every compared channel, prefixed with
// the channel's name ("a1.kurtosis_log"). Baseline::fit takes the median and robust spread of each
// feature over these samples; the recording is scored on its whole record: anomaly_score = mean
// z^2, alarm above BaselineOptions::alarm_threshold (25). This is the setting validated on the
// SpectraQuest set (healthy files of four loads as baseline, eight parts each; the fifth load's
// healthy file scores <= 9.95 and its broken-tooth file >= 50.6; spectraquest_test.cpp).
// Channels are matched by name. The compared channels are the recording's sensor channels
// (sensor_channels) present in every baseline recording; one missing from a baseline recording
// is left out with a note, as is one whose features cannot be computed (too short, constant).
// CAUTION: the crest factor of a record grows with its length (the largest of N Gaussian samples
// sits near sqrt(2 ln N) sigma): keep the recording about as long as the baseline recordings, as
// in the validation (a recording 8x longer than a baseline part reads ~0.1 higher in crest_log).
struct BaselineComparisonOptions {
  BaselineFeatureOptions features;  // the validated feature set (7 octave bands from fs/256, ...)
  BaselineOptions baseline;         // alarm_threshold 25, spread_floor 0.05, min_samples 3
  int segments_per_recording = 8;   // parts per baseline recording, [1, 64]; fewer when a part
                                    // would hold fewer than 4 features.nperseg samples (noted)
  // The wear indicator's threshold per mesh (diag::mesh_name) [dB], where it is known from the
  // reference's own spread (a machine's history: `batch`, docs/cli/batch.md); a mesh not listed
  // is flagged above MeshHarmonicGrowthOptions' threshold_db. Each finite, > 0.
  std::map<std::string, double> wear_threshold_db;

  void validate() const;  // throws diag::InputError "score_against_baseline: <field>: ..."
};

// Throws diag::InputError, naming the baseline recording (names[i], else "baseline recording
// <i+1>") when it is at fault: no baseline recording; a baseline recording with no sensor channel
// of the recording; a compared channel whose sampling rate differs from the recording's (the
// features compare bands at fractions of fs, so the rates must match); no channel left to compare;
// fewer than min_samples baseline samples. `names` is empty or one per baseline recording.
AnalysisBaseline score_against_baseline(const diag::Recording& rec,
                                        std::span<const diag::Recording> baseline,
                                        const BaselineComparisonOptions& opt = {},
                                        std::span<const std::string> names = {});

// The baseline alarm as a finding (the one Finding type: an alarm is a finding, counted and
// listed with the others): kind "baseline", fault kAnomaly, the channel of the largest
// deviation, confidence min(1, score / (2 threshold)) (0.5 at the threshold), evidence
// anomaly_score, threshold, z of the largest deviation and, for a band feature, band_low_hz and
// band_high_hz; the note says in physical terms what moved ("the share of the PSD in 160-320 Hz
// rose", "the kurtosis rose"). `fs_hz`: the rate of each compared channel (band edges are
// fractions of it). Requires b.alarm.
Finding baseline_alarm_finding(const AnalysisBaseline& b,
                               const std::map<std::string, double>& fs_hz,
                               const BaselineComparisonOptions& opt = {});

// Puts a comparison with the baseline into an analysis: r.baseline = b and, when b alarms, the
// alarm as a finding (baseline_alarm_finding, band edges from r.channels' rates) among
// r.findings, most confident first. analyze_file does this itself (and places the alarm in the
// frames that score above the threshold); a result assembled from analyze_recording and
// score_against_baseline gets it here, so that every report shows an alarm as a finding.
void set_baseline(AnalysisResult& r, AnalysisBaseline b, const BaselineComparisonOptions& opt = {});

// ---- Wear against the baseline (detect/baseline/mesh_harmonic_growth.hpp) ----
// Per mesh of gb: the growth of the mesh harmonics against the baseline recordings, the mesh
// frequency read at the recording's speed (r.meshes: the analysis's kinematics) and at each
// baseline recording's own speed, estimated the way the analysis estimates the recording's
// (shaft_kinematics: tacho, else the vibration's mesh ridge near the nominal speed, the nominal
// being the baseline file's recorded input_speed_rpm when it has one, else gb's). Fills
// r.baseline->wear (r.baseline must hold score_against_baseline's result) and, per flagged mesh, a
// finding: kind "wear", fault kWear, the mesh's gears, the mesh frequency, the channel with the
// largest growth, evidence growth_db / threshold_db / mesh_frequency_hz, confidence
// min(1, growth_db / (2 threshold_db)) (0.5 at the threshold, 1 at twice it: the study's worn
// gears of 20 um and more read 5.3-15.7 dB against 4 dB, healthy ones at most 2.0 dB). The
// threshold is MeshHarmonicGrowthOptions' unless `wear_threshold_db` names the mesh
// (BaselineComparisonOptions::wear_threshold_db: a history's, from its reference). A mesh the
// indicator cannot read (a harmonic above fs / 2, a varying speed in the recording or a baseline
// recording: the indicator reads time spectra) is left out with a note in r.baseline->notes.
// `names`: empty or one per baseline recording.
void wear_against_baseline(AnalysisResult& r, const diag::Recording& rec, const diag::Gearbox& gb,
                           std::span<const diag::Recording> baseline,
                           const AnalyzeOptions& opt = {}, std::span<const std::string> names = {},
                           const std::map<std::string, double>& wear_threshold_db = {});

// Scalar features by name, "<channel>/<indicator>" (e.g. "bearing1_along_loa/rms",
// "bearing1_along_loa/tsa/input/z1/fm4", "two_direction/<location>/<mesh>/normal_to_along_db"):
// every scalar indicator of the analysis, for trending (the baseline comparison uses the unit-free
// baseline_features instead, see above). NaN features are left out.
std::map<std::string, double> features(const AnalysisResult& r);

// SpectralPeak-hold decimation for plotting. kMinMax (waveforms): at most max_points / 2 buckets,
// each bucket's min and max kept in x order; kMax (spectra): max_points buckets, each bucket's max,
// so that narrow lines survive and a dB plot does not fill down to the floor. max_points >= 4.
enum class Decimation { kMinMax, kMax };
PlotTrace decimate_for_plot(std::span<const double> x, std::span<const double> y,
                            std::size_t max_points, Decimation mode = Decimation::kMinMax);

}  // namespace detect
