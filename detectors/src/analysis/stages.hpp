// analyze's stages (internal to detectors/src/analysis). analyze_recording runs the
// recording-level stages from its table (analyze.cpp), in order:
//   kinematics (kinematics.hpp)   shaft angles and speeds, the speed report (with a gearbox)
//   angle plans (angle_plans.cpp) one angle plan per shaft, every channel resampled through it
//   channels                      every channel through kChannelStages below, in parallel, each
//                                 stage filling its part of ChannelAnalysis (channel_*.cpp)
//   two_direction_stage (two_direction_stage.cpp)
//   gear_damage_stage, fuse_findings (findings.cpp): the locator, the votes, one finding list
// The baseline comparison (baseline_compare.cpp) and features() (features.cpp) read the result;
// the reports (JSON, text, HTML, curves) are written by the report library (report/).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "detect/analysis/analyze.hpp"
#include "detect/angular/resample.hpp"
#include "detect/spectral/spectrum.hpp"
#include "diag/util/number_format.hpp"
#include "diag/util/parallel_for.hpp"
#include "kinematics.hpp"

namespace detect::analysis_stages {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();
// TSA and order spectra keep orders up to 0.72 x the Nyquist order unattenuated (tsa.hpp): the
// angular sampling is at least 2.8 x the highest order of interest.
inline constexpr double kOrderOversampling = 2.8;
inline constexpr int kMaxSamplesPerRev = 1 << 14;

inline std::string fmt(double v, int prec = 3) { return diag::format_significant(v, prec); }

inline std::size_t pow2_at_least(double v) {
  std::size_t p = 1;
  while (static_cast<double>(p) < v) p <<= 1;
  return p;
}

inline std::size_t pow2_at_most(std::size_t v) {
  std::size_t p = 1;
  while (p * 2 <= v) p <<= 1;
  return p;
}

// What every stage after the kinematics reads.
struct AnalysisContext {
  const diag::Recording& rec;
  const diag::Gearbox* gb;  // null: no gearbox (the channel stages that need one are skipped)
  const AnalyzeOptions& opt;
  const ShaftKinematics& kin;
  const std::vector<AnalysisMesh>& meshes;  // the result's, at the measured mean speed
  int input = -1;                           // the input shaft
  double input_hz = 0;                      // its mean speed [Hz]
  double max_input_order = 0;               // highest order of interest, input-shaft orders
  bool order_domain = false;                // varying speed: spectra in the order domain
  std::size_t plot_points = 0;
  std::vector<bool> sensor;   // per signal: a sensor channel (votes in findings)
  std::vector<bool> located;  // per bearing: some sensor channel sits at it
};

// The angle-plans stage: one plan per shaft for every channel of the common rate and length
// (resample.hpp: its taps are computed once per output sample for all channels), the channels
// resampled through each plan.
struct AngularRecords {
  double plan_fs = 0;  // the rate and length of the channels that share the plans
  std::size_t plan_n = 0;
  ResampleOptions order_ro;          // the order spectrum's (and order domain's) sampling
  std::vector<double> order_pulses;  // input-shaft revolutions for the order domain
  std::optional<AnglePlan> order_plan;
  std::vector<std::optional<AngleResampled>> order_resampled;             // per signal
  std::vector<std::vector<std::optional<AngleResampled>>> tsa_resampled;  // per shaft, signal

  bool shares_plans(const diag::Signal& s) const {
    return s.fs_hz == plan_fs && s.samples.size() == plan_n;
  }
};
AngularRecords angle_plans_stage(const AnalysisContext& ctx);

// TSA angular resolution of shaft s: 2.8 x the highest order its gear metrics examine.
int tsa_samples_per_rev(const diag::Gearbox& gb, std::size_t s, const AnalyzeOptions& opt);

// The `count` largest local maxima (a[k] > a[k-1], a[k] >= a[k+1]) of a spectrum up to max_hz,
// descending amplitude, equal amplitudes by ascending frequency.
std::vector<SpectralPeak> largest_peaks(const Spectrum& s, int count, double max_hz);
// The part of a curve in [lo, hi], peak-hold decimated for plotting.
PlotTrace slice_for_plot(const std::vector<double>& x, const std::vector<double>& y, double lo,
                         double hi, std::size_t max_points);

// ---- per-channel stages ----
// The time-domain indicators of a channel's moments (time_stage's, the whole-record stage's).
TimeIndicators time_indicators(const Moments& mo);
// The Welch segment length for a record of n samples (spectra_stage's, the whole-record's).
std::size_t welch_segment(const AnalyzeOptions& opt, std::size_t n);

// The record a channel's spectra are taken of: the channel itself, or at varying speed the
// channel at uniform input-shaft angles read as a record at the mean speed (its rate
// samples_per_rev x the mean input speed). `angular` is the channel at input-shaft angles (the
// order spectrum's), null when it could not be resampled (the reason is in the channel's notes;
// in the order domain the channel then has no spectra: spectral() is null).
struct SpectralRecord {
  const diag::Signal* time = nullptr;
  const AngleResampled* angular = nullptr;
  std::optional<AngleResampled> own;  // resampled on its own (not sharing the plans)
  diag::Signal angle_signal;          // the order-domain record
  bool order_domain = false;
  std::string angular_error;      // why the channel could not be resampled (steady: said by the
                                  // order spectrum stage, where the note has always been)
  bool angular_unneeded = false;  // steady speed, no plot: `angular` not made (no reader)
  const diag::Signal* spectral() const {
    return order_domain ? (angular ? &angle_signal : nullptr) : time;
  }
};

// What the stages of one channel share: the recording-level context (kinematics, plans,
// options), the channel, the ChannelAnalysis they fill (its notes say what was skipped and why)
// and what one stage leaves for a later one. Channels run in parallel, each with its own
// ChannelWork; the context and the plans are read only.
struct ChannelWork {
  const AnalysisContext& ctx;
  const AngularRecords& ang;
  std::size_t index;           // the channel's index in ctx.rec.signals
  const diag::Signal& signal;  // ctx.rec.signals[index]
  ChannelAnalysis& out;
  SpectralRecord record;  // the spectral-record stage's (spectral() null: no spectra)
  Spectrum spectrum;      // the whole amplitude spectrum (the sidebands, then two directions)
  Spectrum envelope;      // the whole envelope spectrum (the bearing metrics)
};

// What a stage needs of its channel; a stage whose needs are not met is skipped. Each need, once
// unmet, stays unmet for the later stages, so a skip is what an early return would be.
enum ChannelNeed : unsigned {
  kVibrationChannel = 1u << 0,  // ChannelAnalysis::vibration (set by the time stage)
  kSpectralRecord = 1u << 1,    // the spectral-record stage gave a record to take spectra of
  kSensorChannel = 1u << 2,     // ChannelAnalysis::sensor: a vibration sensor (votes)
  kGearbox = 1u << 3,           // a gearbox description
  kTraces = 1u << 4,            // AnalyzeOptions::traces: the plot-only curves are asked for
};
bool channel_needs_met(const ChannelWork& w, unsigned needs);

// The channel's identity and time-domain indicators.
void time_stage(ChannelWork& w);
// The record the spectra are taken of (a note and no record below 64 samples).
void spectral_record_stage(ChannelWork& w);
// Amplitude spectrum (kept whole in w.spectrum) and Welch PSD.
void spectra_stage(ChannelWork& w);
// The spectrogram of the record in time, on the bounded grid of SpectrogramTrace.
void spectrogram_stage(ChannelWork& w);
// The kurtogram band of the channel in time and its envelope spectrum (in the order domain: the
// envelope in time resampled like the channel), kept whole in w.envelope.
void envelope_stage(ChannelWork& w);
// Fault bands, band metrics and diagnose_bearings_from_signal for the bearings this channel
// sees.
void bearing_stage(ChannelWork& w);
// Mesh harmonics and sideband families of every mesh.
void sideband_stage(ChannelWork& w);
// The order spectrum in input-shaft orders.
void order_spectrum_stage(ChannelWork& w);
// TSA per shaft with gears and each gear's metrics (from the shared plans when the channel
// shares them).
void tsa_stage(ChannelWork& w);

// How far the envelope trace and peaks of a spectral record of rate fs_hz are kept [Hz].
double envelope_plot_max_hz(const AnalysisContext& ctx, double fs_hz);
// The envelope peaks, trace and bearing band metrics of a channel from its envelope spectrum.
void envelope_results(const AnalysisContext& ctx, const Spectrum& env, double fs_hz,
                      ChannelAnalysis& c);

// One row per stage, run in this order on every channel: adding a detector is one stage
// function above and one row here. The name keys the stage's CPU time in the result
// ("channel_cpu.<name>" in AnalysisResult::timing_s).
struct ChannelStage {
  const char* name;
  unsigned needs;  // ChannelNeed bits
  void (*run)(ChannelWork&);
};
inline constexpr ChannelStage kChannelStages[] = {
    {"time", 0, time_stage},
    {"spectral_record", kVibrationChannel, spectral_record_stage},
    {"spectra", kSpectralRecord, spectra_stage},
    {"spectrogram", kSpectralRecord | kTraces, spectrogram_stage},  // only drawn
    {"envelope", kSpectralRecord, envelope_stage},
    {"bearing", kSpectralRecord | kSensorChannel | kGearbox, bearing_stage},
    {"sidebands", kSpectralRecord | kGearbox, sideband_stage},
    {"order_spectrum", kSpectralRecord | kGearbox, order_spectrum_stage},
    {"tsa", kSpectralRecord | kGearbox, tsa_stage},
};

// ---- recording-level stages ----
// Along/normal-LOA pairs at one location: mesh-harmonic energies in both directions.
void two_direction_stage(const AnalysisContext& ctx, const std::vector<Spectrum>& spectra,
                         AnalysisResult& r);
// The damaged-shaft locator on the kinematics' angles.
void gear_damage_stage(const AnalysisContext& ctx, AnalysisResult& r);
// One finding list: the locator's, the sideband vote per mesh, the bearing vote per bearing;
// most confident first.
void fuse_findings(const AnalysisContext& ctx, AnalysisResult& r);

}  // namespace detect::analysis_stages
