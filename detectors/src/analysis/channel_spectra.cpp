// analyze's per-channel stages: time-domain indicators, the spectral record (the channel or its
// order-domain form), amplitude spectrum, Welch PSD and order spectrum (stages.hpp).
#include <algorithm>

#include "detect/angular/order_spectrum.hpp"
#include "detect/indicators/indicators.hpp"
#include "detect/spectral/fft.hpp"
#include "detect/spectral/welch.hpp"
#include "diag/error.hpp"
#include "stages.hpp"

namespace detect::analysis_stages {

std::vector<SpectralPeak> largest_peaks(const Spectrum& s, int count, double max_hz) {
  // The `count` largest local maxima kept sorted as the scan goes (descending amplitude, equal
  // amplitudes by ascending frequency): once `count` are held, a bin is looked at further only
  // when it exceeds the smallest of them, so the scan costs about one compare per bin.
  std::vector<SpectralPeak> top;
  const std::size_t want = static_cast<std::size_t>(std::max(count, 0));
  if (want == 0) return top;
  top.reserve(want + 1);
  const auto& a = s.amplitude;
  const auto& f = s.frequency_hz;
  // Bins 1 .. a.size() - 2 up to max_hz.
  const std::size_t end = std::min<std::size_t>(
      a.size() < 2 ? 0 : a.size() - 1,
      static_cast<std::size_t>(std::upper_bound(f.begin(), f.end(), max_hz) - f.begin()));
  double least = -kInf;  // the smallest amplitude kept, once `want` are kept
  for (std::size_t k = 1; k < end; ++k) {
    if (!(a[k] > least)) continue;
    if (!(a[k] > a[k - 1] && a[k] >= a[k + 1])) continue;
    const auto at = std::upper_bound(
        top.begin(), top.end(), a[k],
        [](double v, const SpectralPeak& p) { return v > p.amplitude; });  // after equal ones
    top.insert(at, SpectralPeak{f[k], a[k]});
    if (top.size() > want) top.pop_back();
    if (top.size() == want) least = top.back().amplitude;
  }
  return top;
}

PlotTrace slice_for_plot(const std::vector<double>& x, const std::vector<double>& y, double lo,
                         double hi, std::size_t max_points) {
  auto b = std::lower_bound(x.begin(), x.end(), lo);
  auto e = std::upper_bound(x.begin(), x.end(), hi);
  const auto i0 = static_cast<std::size_t>(b - x.begin());
  const auto n = static_cast<std::size_t>(e - b);
  return decimate_for_plot(std::span<const double>(x).subspan(i0, n),
                           std::span<const double>(y).subspan(i0, n), max_points, Decimation::kMax);
}

void time_stage(ChannelWork& w) {
  const diag::Signal& sig = w.signal;
  ChannelAnalysis& c = w.out;
  c.identity() = sig.identity();
  c.samples = sig.samples.size();
  // Spectra for what vibrates (sensors, and the simulator's mesh force and deflection); the
  // time indicators only for angles, speeds and other quantities.
  c.vibration = sig.role == diag::Role::kVibration || sig.role == diag::Role::kForce ||
                sig.role == diag::Role::kDisplacement;
  c.sensor = w.ctx.sensor[w.index];
  c.time = time_indicators(moments(sig.samples));
}

TimeIndicators time_indicators(const Moments& mo) {
  return {mo.rms(), mo.peak(), mo.crest_factor(), mo.kurtosis(), mo.skewness()};
}

std::size_t welch_segment(const AnalyzeOptions& opt, std::size_t n) {
  return std::min(opt.welch_nperseg, pow2_at_most(n));
}

void spectral_record_stage(ChannelWork& w) {
  const AnalysisContext& ctx = w.ctx;
  const AngularRecords& ang = w.ang;
  const std::size_t ci = w.index;
  const diag::Signal& sig = w.signal;
  ChannelAnalysis& c = w.out;
  if (sig.samples.size() < 64) {  // no record: no later stage that needs one runs
    c.notes.push_back("fewer than 64 samples: no spectra");
    return;
  }
  SpectralRecord& out = w.record;
  out.time = &sig;
  out.order_domain = ctx.order_domain;
  if (!ctx.gb) return;
  // At steady speed without a plot the channel at input-shaft angles has no reader (the order
  // spectrum is only drawn): not made when the order plan could be (a channel the plan cannot
  // take still tries on its own, so that a failure gives the same note with or without a plot).
  if (!ctx.order_domain && !ctx.opt.traces && ang.order_plan && ang.shares_plans(sig) &&
      sig.samples.size() >= 64) {
    out.angular_unneeded = true;
    return;
  }
  try {
    if (!ang.order_resampled.empty() && ang.order_resampled[ci]) {
      out.angular = &*ang.order_resampled[ci];
    } else {
      out.own = resample_by_angle(sig.samples, sig.fs_hz, ang.order_pulses, ang.order_ro);
      out.angular = &*out.own;
    }
  } catch (const diag::InputError& e) {
    out.angular_error = e.what();
    if (ctx.order_domain) c.notes.push_back("order-domain spectra skipped: " + out.angular_error);
  }
  if (!ctx.order_domain || !out.angular) return;
  diag::Signal& a = out.angle_signal;
  a.identity() = sig.identity();
  a.fs_hz = out.angular->samples_per_rev * ctx.input_hz;
  a.samples = out.angular->samples;
}

void spectra_stage(ChannelWork& w) {
  const AnalysisContext& ctx = w.ctx;
  const diag::Signal& spectral = *w.record.spectral();
  ChannelAnalysis& c = w.out;
  const AnalyzeOptions& opt = ctx.opt;
  const std::span<const double> x(spectral.samples);
  const double fs = spectral.fs_hz;
  SpectrumOptions so;
  so.fs_hz = fs;
  so.window = opt.spectrum_window;
  so.remove_mean = true;
  so.nfft = next_fast_length(x.size());  // zero-padded to a fast length (analyze.hpp)
  Spectrum& sp = w.spectrum;
  sp = amplitude_spectrum(x, so);
  c.spectrum_resolution_hz = sp.resolution_hz;
  c.spectrum_enbw_hz = sp.enbw_hz;
  c.spectrum_peaks = largest_peaks(sp, opt.peaks_reported, 0.5 * fs);
  if (opt.keep_spectra) {
    c.spectrum_power.resize(sp.amplitude.size());
    for (std::size_t k = 0; k < sp.amplitude.size(); ++k) {
      c.spectrum_power[k] = static_cast<float>(sp.amplitude[k] * sp.amplitude[k]);
    }
  }
  WelchOptions wo;
  wo.fs_hz = fs;
  wo.nperseg = welch_segment(opt, x.size());
  if (!opt.traces) {  // the PSD is only drawn: its layout is what the report states
    c.psd_resolution_hz = fs / static_cast<double>(wo.fft_length());
    c.psd_segments = wo.segments(x.size());
    return;
  }
  c.spectrum = decimate_for_plot(sp.frequency_hz, sp.amplitude, ctx.plot_points, Decimation::kMax);
  const Psd psd = welch(x, wo);
  c.psd = decimate_for_plot(psd.frequency_hz, psd.value, ctx.plot_points, Decimation::kMax);
  c.psd_resolution_hz = psd.resolution_hz;
  c.psd_segments = psd.segments;
}

void order_spectrum_stage(ChannelWork& w) {
  const AnalysisContext& ctx = w.ctx;
  const SpectralRecord& rec = w.record;
  ChannelAnalysis& c = w.out;
  if (!rec.angular) {
    if (!rec.order_domain && !rec.angular_unneeded)
      c.notes.push_back("order spectrum skipped: " + rec.angular_error);
    return;
  }
  if (!ctx.opt.traces) return;  // the order spectrum is only drawn
  try {
    const OrderSpectrum os = order_spectrum(*rec.angular);
    c.order_spectrum =
        slice_for_plot(os.order, os.amplitude, 0,
                       std::min(1.2 * ctx.max_input_order, os.order.back()), ctx.plot_points);
  } catch (const diag::InputError& e) {
    c.notes.push_back(std::string("order spectrum skipped: ") + e.what());
  }
}

}  // namespace detect::analysis_stages
