// analyze's per-channel stages: the envelope spectrum in the kurtogram's band and the bearings
// (fault bands, band metrics, diagnose_bearings_from_signal) (stages.hpp).
#include <algorithm>
#include <cmath>
#include <map>

#include "detect/bearing/bearing_diagnosis.hpp"
#include "detect/bearing/bearing_faults.hpp"
#include "detect/gear/fault_bands.hpp"
#include "detect/spectral/envelope.hpp"
#include "detect/spectral/kurtogram.hpp"
#include "diag/error.hpp"
#include "stages.hpp"

namespace detect::analysis_stages {

namespace {

// The kurtogram's deepest level for n samples: log2(n) - 7 (a level-L band needs 2^(L+7)).
int kurtogram_level_for(std::size_t n, int max_level) {
  return std::min(max_level, static_cast<int>(std::floor(std::log2(static_cast<double>(n)))) - 7);
}

// The part of a record the band is chosen on: its middle kKurtogramSamples (all of a shorter
// record). The kurtogram costs ~12 pairs of inverse FFTs of the record's length (kurtogram.hpp:
// one row per level, every band of a row together as long as the record): 40 % of analyze on
// the 39-channel simulation. A band's kurtosis is a mean over time (of |c|^4 and |c|^2), so a
// stationary or cyclostationary record's middle 2^16 samples estimate it as the whole does:
// 3.3 s at 20 kHz, >= 100 revolutions of a shaft above 30 Hz and > 150 impacts of a bearing
// fault line above 50 Hz, 1024 samples in each band of the deepest level 6 (Antoni 2007 asks
// 2^7). The middle, not the start, to keep clear of an acquisition's start-up transient.
constexpr std::size_t kKurtogramSamples = std::size_t{1} << 16;
std::span<const double> kurtogram_excerpt(std::span<const double> x) {
  if (x.size() <= kKurtogramSamples) return x;
  return x.subspan((x.size() - kKurtogramSamples) / 2, kKurtogramSamples);
}

double envelope_spectrum_max_hz(const AnalysisContext& ctx, double fs_hz) {
  // What envelope_results and bearing_stage read: the plot and peaks to envelope_plot_max_hz,
  // the bearings' fault bands to their top edge.
  double top = envelope_plot_max_hz(ctx, fs_hz);
  if (const diag::Gearbox* gb = ctx.gb) {
    for (const auto& b : gb->bearings()) {
      const int s = gb->shaft_index(b.shaft);
      if (s < 0) continue;
      const auto f = bearing_frequencies(b, ctx.kin.speeds[static_cast<std::size_t>(s)].speed_hz);
      for (const FaultBand& fb : bearing_fault_bands(f, ctx.opt.fault_bands))
        top = std::max(top, fb.high_hz);
    }
  }
  return std::min(top, 0.5 * fs_hz);
}

// The band view of the decision as the report draws it: every scored harmonic with its
// prominence and whether the decision counted it, and the spectrum it was read on up to 1.1 x the
// highest of them.
void decision_view(const BearingDiagnosis& d, double line_threshold_db, std::size_t plot_points,
                   BearingAnalysis& ba) {
  static const char* kLabel[] = {"FTF", "BPFO", "BPFI", "2BSF"};
  double top = 0;
  for (const FamilyScore& f : ba.diagnosis.band_decision.families) {
    const int fam = f.fault == BearingFault::kCage        ? 0
                    : f.fault == BearingFault::kOuterRace ? 1
                    : f.fault == BearingFault::kInnerRace ? 2
                                                          : 3;
    for (std::size_t h = 0; h < f.lines.size(); ++h) {
      const LineMeasurement& m = f.lines[h];
      BearingLine l;
      l.family = fam;
      l.harmonic = static_cast<int>(h) + 1;
      l.label = (h == 0 ? "" : std::to_string(h + 1) + "x") + kLabel[fam];
      l.expected_hz = m.expected_hz;
      l.found_hz = m.valid ? m.frequency_hz : m.expected_hz;
      l.prominence_db = m.valid ? m.prominence_db : 0.0;
      l.seen = m.valid && m.prominence_db >= line_threshold_db;
      top = std::max(top, m.expected_hz);
      ba.lines.push_back(std::move(l));
    }
  }
  if (top > 0 && d.band_ses_frequency_hz.size() > 2) {
    ba.decision_envelope =
        slice_for_plot(d.band_ses_frequency_hz, d.band_ses_amplitude, 0, 1.1 * top, plot_points);
  }
}

}  // namespace

void envelope_stage(ChannelWork& w) {
  const AnalysisContext& ctx = w.ctx;
  const AngularRecords& ang = w.ang;
  const SpectralRecord& rec = w.record;
  ChannelAnalysis& c = w.out;
  const AnalyzeOptions& opt = ctx.opt;
  const diag::Signal& sig = *rec.time;
  const diag::Signal& spectral = *rec.spectral();
  const std::span<const double> xt(sig.samples);
  {
    std::vector<double> t(xt.size());
    for (std::size_t i = 0; i < t.size(); ++i) t[i] = static_cast<double>(i) / sig.fs_hz;
    c.waveform = decimate_for_plot(t, xt, ctx.plot_points, Decimation::kMinMax);
  }
  // The kurtogram and the envelope spectrum are for the bearings and impacts a vibration sensor
  // records (role vibration, channels.hpp); a force or displacement channel (a simulation's mesh
  // force, friction, transmission error) has none, and nothing downstream reads its envelope.
  if (!c.sensor) return;
  // The demodulation band is chosen and applied in time (in the order domain too: a resonance
  // is fixed in Hz).
  EnvelopeSpectrumOptions eo;
  eo.fs_hz = sig.fs_hz;
  const double nyq_t = 0.5 * sig.fs_hz;
  const int level = kurtogram_level_for(xt.size(), opt.kurtogram_max_level);
  if (level >= 1) {
    KurtogramOptions ko;
    ko.fs_hz = sig.fs_hz;
    ko.max_level = level;
    const Kurtogram kg = fast_kurtogram(kurtogram_excerpt(xt), ko);
    c.kurtogram_level = kg.level;
    c.kurtogram_kurtosis = kg.kurtosis;
    c.kurtogram = kg.levels;
    eo.band_low_hz = std::max(0.0, kg.low_hz());
    eo.band_high_hz = std::min(nyq_t, kg.high_hz());
  } else {
    c.notes.push_back("record too short for the kurtogram: envelope of the whole band");
  }
  c.envelope_low_hz = eo.band_low_hz;
  c.envelope_high_hz = eo.band_high_hz == 0 ? nyq_t : eo.band_high_hz;
  Spectrum& env = w.envelope;
  if (rec.order_domain) {
    // The envelope in time, resampled like the channel, its spectrum read at the mean speed
    // (the envelope order spectrum).
    const std::vector<double> env_t =
        band_envelope(xt, {sig.fs_hz, eo.band_low_hz, eo.band_high_hz});
    const AngleResampled env_a =
        ang.order_plan && ang.shares_plans(sig)
            ? resample_by_angle(env_t, *ang.order_plan)
            : resample_by_angle(env_t, sig.fs_hz, ang.order_pulses, ang.order_ro);
    SpectrumOptions es;
    es.fs_hz = spectral.fs_hz;
    es.window = eo.window;
    es.scaling = eo.scaling;
    es.remove_mean = true;
    env = amplitude_spectrum(env_a.samples, es);
  } else {
    // The middle fast-length part of the record (its DFTs at FFTW's full speed, envelope.hpp
    // fast_length_at_most: ts10's 200000 samples are kept whole, CWRU's 121265 cut to 120960),
    // the spectrum computed only as far as it is read (envelope.hpp max_frequency_hz).
    eo.max_frequency_hz = envelope_spectrum_max_hz(ctx, sig.fs_hz);
    env = envelope_spectrum(fast_length_middle(xt), eo);
  }
  envelope_results(ctx, env, spectral.fs_hz, c);
}

double envelope_plot_max_hz(const AnalysisContext& ctx, double fs_hz) {
  // Kept for plotting up to 5 x the highest bearing fault line (else 1 kHz), at most Nyquist.
  double env_max = ctx.opt.envelope_plot_max_hz;
  const diag::Gearbox* gb = ctx.gb;
  if (env_max == 0) {
    env_max = 1000.0;
    if (gb && !gb->bearings().empty()) {
      double top = 0;
      for (const auto& b : gb->bearings()) {
        const int s = gb->shaft_index(b.shaft);
        if (s < 0) continue;
        const auto f = bearing_frequencies(b, ctx.kin.speeds[static_cast<std::size_t>(s)].speed_hz);
        top = std::max({top, f.bpfi_hz, f.bpfo_hz, f.ball_fault_hz});
      }
      if (top > 0) env_max = 5 * top;
    }
  }
  return std::min(env_max, 0.5 * fs_hz);
}

void envelope_results(const AnalysisContext& ctx, const Spectrum& env, double fs_hz,
                      ChannelAnalysis& c) {
  const double env_max = envelope_plot_max_hz(ctx, fs_hz);
  c.envelope_peaks = largest_peaks(env, ctx.opt.peaks_reported, env_max);
  if (ctx.opt.keep_spectra) {  // up to where the peaks are sought
    c.envelope_resolution_hz = env.resolution_hz;
    c.envelope_power.clear();
    for (std::size_t k = 0; k < env.amplitude.size() && env.frequency_hz[k] <= env_max; ++k) {
      c.envelope_power.push_back(static_cast<float>(env.amplitude[k] * env.amplitude[k]));
    }
  }
  c.envelope = slice_for_plot(env.frequency_hz, env.amplitude, 0, env_max, ctx.plot_points);
  const SpectrumView ev{env.frequency_hz, env.amplitude};
  for (BearingAnalysis& ba : c.bearings)
    ba.metrics = fault_band_metrics(ev, ba.bands, SpectrumScale::kAmplitude);
}

void bearing_stage(ChannelWork& w) {
  const AnalysisContext& ctx = w.ctx;
  const diag::Signal& spectral = *w.record.spectral();
  const Spectrum& env = w.envelope;
  ChannelAnalysis& c = w.out;
  const diag::Gearbox* gb = ctx.gb;
  if (gb->bearings().empty()) return;
  const AnalyzeOptions& opt = ctx.opt;
  const auto& speeds = ctx.kin.speeds;
  // diagnose_bearings_from_signal once per shaft, on the bearings this channel sees: those at its
  // location, and those no sensor channel sits at.
  std::map<int, std::vector<diag::BearingSpec>> by_shaft;
  for (std::size_t b = 0; b < ctx.located.size(); ++b) {
    const diag::BearingSpec& spec = gb->bearings()[b];
    const int s = gb->shaft_index(spec.shaft);
    if (s >= 0 && (!ctx.located[b] || c.location == spec.name)) by_shaft[s].push_back(spec);
  }
  std::map<std::string, std::pair<const BearingStatus*, const BearingDiagnosis*>> status;
  std::vector<BearingDiagnosis> diagnoses;
  diagnoses.reserve(by_shaft.size());
  BearingDiagnosisOptions bo = opt.bearing;
  const std::size_t n = spectral.samples.size();
  bo.kurtogram_max_level = kurtogram_level_for(n, bo.kurtogram_max_level);
  for (const auto& [s, specs] : by_shaft) {
    std::string names;
    for (const auto& b : specs) names += (names.empty() ? "" : ", ") + b.name;
    if (bo.kurtogram_max_level < 1) {
      c.notes.push_back("bearing diagnosis (" + names + ") skipped: " + std::to_string(n) +
                        " samples, fewer than 2^8");
      continue;
    }
    try {
      diagnoses.push_back(diagnose_bearings_from_signal(
          spectral, speeds[static_cast<std::size_t>(s)].speed_hz, specs, bo));
    } catch (const diag::InputError& e) {
      c.notes.push_back("bearing diagnosis (" + names + ") skipped: " + e.what());
      continue;
    }
    for (const BearingStatus& st : diagnoses.back().bearings)
      status[st.bearing] = {&st, &diagnoses.back()};
  }
  const SpectrumView ev{env.frequency_hz, env.amplitude};
  for (const auto& [s, specs] : by_shaft) {
    for (const auto& spec : specs) {
      BearingAnalysis ba;
      ba.bearing = spec.name;
      ba.shaft = spec.shaft;
      ba.frequencies = bearing_frequencies(spec, speeds[static_cast<std::size_t>(s)].speed_hz);
      ba.bands = bearing_fault_bands(ba.frequencies, opt.fault_bands);
      ba.metrics = fault_band_metrics(ev, ba.bands, SpectrumScale::kAmplitude);
      if (const auto it = status.find(spec.name); it != status.end()) {
        ba.diagnosed = true;
        ba.diagnosis = *it->second.first;
        ba.band_centre_hz = it->second.second->band_centre_hz;
        ba.band_width_hz = it->second.second->band_width_hz;
        decision_view(*it->second.second, bo.decision.line_threshold_db, ctx.plot_points, ba);
      }
      c.bearings.push_back(std::move(ba));
    }
  }
  // The description's order, whatever the shaft grouping.
  auto order = [&](const std::string& name) {
    const auto& all = gb->bearings();
    return std::find_if(all.begin(), all.end(),
                        [&](const diag::BearingSpec& b) { return b.name == name; }) -
           all.begin();
  };
  std::stable_sort(c.bearings.begin(), c.bearings.end(),
                   [&](const BearingAnalysis& a, const BearingAnalysis& b) {
                     return order(a.bearing) < order(b.bearing);
                   });
}

}  // namespace detect::analysis_stages
