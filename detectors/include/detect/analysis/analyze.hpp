// Offline analysis of a whole recording (`geardiag analyze`): every detector of the library run
// on every channel, tied to the gearbox description when there is one, collected into one result
// that prints, serialises to JSON (to_json) and renders to HTML (html_report.hpp).
//
// Per channel (tacho and angle channels get the time-domain indicators only):
//  - time-domain indicators: RMS, peak, crest factor, kurtosis, skewness (indicators.hpp);
//  - amplitude spectrum of the whole record (spectrum.hpp, Hann, peak scaling) and Welch PSD
//    (welch.hpp); the largest spectral peaks;
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
//    is that of a constant nominal speed (pulse times k / f_shaft): fine for a steady rig, smeared
//    when the speed drifts; the result says which was used;
//  - every bearing of the description: fault frequencies, fault bands and band metrics on the
//    envelope spectrum, and the bearing decision (bearing_faults.hpp, fault_bands.hpp) on the
//    channels at that bearing (location == bearing name; every vibration channel when none is);
//  - the two-direction comparison (two_direction.hpp): for each location with an along_loa and a
//    normal_loa channel, the mesh-harmonic energies in both and their normal-to-along ratio [dB].
// Findings (AnalysisFinding) summarise what points at a shaft, gear or bearing, each with a
// confidence and a note. Steps that cannot run on this record (too few revolutions for a TSA, a
// record too short for the kurtogram) are skipped with a note, not an error: they are outcomes.
#pragma once

#include <cstddef>
#include <limits>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "detect/angular/tsa.hpp"
#include "detect/gear/bearing_faults.hpp"
#include "detect/gear/fault_bands.hpp"
#include "detect/gear/sidebands.hpp"
#include "detect/gear/two_direction.hpp"
#include "detect/indicators/indicators.hpp"
#include "detect/spectral/window.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/recording.hpp"

namespace detect {

struct AnalyzeOptions {
  WindowType spectrum_window = WindowType::kHann;  // amplitude spectrum window (Hann: 1.5-bin
                                                   // ENBW, resolves sidebands one shaft apart)
  std::size_t welch_nperseg = 4096;  // Welch segment [samples], [8, 2^24]; shortened to the
                                     // largest power of two that fits a short record
  int kurtogram_max_level = 6;       // [1, 12]; lowered to log2(N) - 7 for short records
  int tacho_pulses_per_rev = 1;      // pulses per revolution of every tacho channel, >= 1
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
  BearingDecisionOptions bearing;           // bearing decision thresholds
  TwoDirectionOptions two_direction;        // mesh harmonics summed in the two-direction ratio

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

struct BearingAnalysis {
  std::string bearing, shaft;
  BearingFrequencies frequencies;
  std::vector<FaultBand> bands;
  FaultBandMetrics metrics;  // on the envelope spectrum (amplitude scale)
  BearingDecision decision;
};

struct ChannelAnalysis {
  std::string name, unit, location;
  diag::Direction direction = diag::Direction::kUnspecified;
  double fs_hz = 0;
  std::size_t samples = 0;
  bool vibration = true;  // false for tacho and angle channels: only `time` is filled
  TimeIndicators time;
  double spectrum_resolution_hz = 0;
  double spectrum_enbw_hz = 0;
  std::vector<SpectralPeak> spectrum_peaks;  // largest local maxima, descending amplitude
  PlotTrace spectrum;                        // amplitude spectrum [unit] vs Hz
  PlotTrace psd;                             // Welch PSD [unit^2/Hz] vs Hz
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

struct AnalysisMesh {
  std::string name, driver, driven;
  double frequency_hz = 0;
};

// One conclusion, in the shape of `geardiag attribute --json` findings. Fields that do not apply
// stay empty (strings), empty (gears) or NaN (frequency_hz) and are left out of the JSON.
struct AnalysisFinding {
  std::string kind;  // "gear_sidebands", "bearing" (future: "gear_damage", "anomaly")
  std::string shaft;
  std::vector<std::string> gears;
  std::string bearing;
  std::string fault;  // bearing: "cage", "outer_race", "inner_race", "ball"
  double frequency_hz = std::numeric_limits<double>::quiet_NaN();
  std::string channel;    // the channel that shows it best
  double confidence = 0;  // [0, 1]
  std::string note;
};

// Integration point for baselines (detect/baseline, not in this build): a filled value renders
// in the report and the JSON ("anomaly_score", "alarm", "baseline_deviations").
struct AnalysisBaselineDeviation {
  std::string feature;  // a key of features()
  double value = 0, baseline_mean = 0, baseline_std = 0, z = 0;
};
struct AnalysisBaseline {
  double anomaly_score = 0;
  double threshold = 0;
  bool alarm = false;
  std::vector<AnalysisBaselineDeviation> deviations;  // largest |z| first
};

struct AnalysisResult {
  std::string gearbox_name;  // empty without a gearbox
  std::string input_shaft;   // the gearbox's input shaft (order spectra are in its orders)
  double duration_s = 0;
  std::vector<AnalysisShaftSpeed> shafts;
  std::vector<AnalysisMesh> meshes;
  std::vector<ChannelAnalysis> channels;
  std::vector<TwoDirectionRow> two_direction;
  std::vector<AnalysisFinding> findings;  // every finding, most confident first
  std::optional<AnalysisBaseline> baseline;
  std::vector<std::string> notes;  // recording-level notes (speed source, skipped steps)
};

// Throws diag::InputError for bad options, a recording without signals, or a signal that fails
// diag::validate. `gb` may be null: then only the unit-free indicators and spectra are computed.
AnalysisResult analyze_recording(const diag::Recording& rec, const diag::Gearbox* gb,
                                 const AnalyzeOptions& opt = {});

// Scalar features by name, "<channel>/<indicator>" (e.g. "bearing1_along_loa/rms",
// "bearing1_along_loa/tsa/input/z1/fm4", "two_direction/<location>/<mesh>/normal_to_along_db"):
// the vector a baseline is fitted on. NaN features are left out.
std::map<std::string, double> features(const AnalysisResult& r);

// JSON with stable keys (README "geardiag analyze"). Amplitudes are in each channel's "unit"
// (energies in unit^2, PSD in unit^2/Hz); keys with a physical unit of their own carry it
// (frequency_hz, speed_hz, ..._db). Traces (plots) are not serialised.
nlohmann::json to_json(const AnalysisResult& r);

// A readable multi-line summary for the terminal.
std::string format_summary(const AnalysisResult& r);

// SpectralPeak-hold decimation for plotting. kMinMax (waveforms): at most max_points / 2 buckets,
// each bucket's min and max kept in x order; kMax (spectra): max_points buckets, each bucket's max,
// so that narrow lines survive and a dB plot does not fill down to the floor. max_points >= 4.
enum class Decimation { kMinMax, kMax };
PlotTrace decimate_for_plot(std::span<const double> x, std::span<const double> y,
                            std::size_t max_points, Decimation mode = Decimation::kMinMax);

}  // namespace detect
