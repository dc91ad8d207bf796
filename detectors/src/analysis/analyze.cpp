#include "detect/analysis/analyze.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <sstream>
#include <thread>

#include "detect/angular/order_spectrum.hpp"
#include "detect/angular/resample.hpp"
#include "detect/angular/tacho.hpp"
#include "detect/gear/bearing_diagnosis.hpp"
#include "detect/spectral/envelope.hpp"
#include "detect/spectral/kurtogram.hpp"
#include "detect/spectral/spectrum.hpp"
#include "detect/spectral/welch.hpp"
#include "diag/error.hpp"
#include "diag/io/channels.hpp"
#include "kinematics.hpp"

namespace detect {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
// TSA and order spectra keep orders up to 0.72 x the Nyquist order unattenuated (tsa.hpp): the
// angular sampling is at least 2.8 x the highest order of interest.
constexpr double kOrderOversampling = 2.8;
constexpr int kMaxSamplesPerRev = 1 << 14;

void require(bool ok, const std::string& field, const std::string& reason) {
  if (!ok) throw diag::InputError("analyze: " + field + ": " + reason);
}

std::size_t pow2_at_least(double v) {
  std::size_t p = 1;
  while (static_cast<double>(p) < v) p <<= 1;
  return p;
}

std::size_t pow2_at_most(std::size_t v) {
  std::size_t p = 1;
  while (p * 2 <= v) p <<= 1;
  return p;
}

std::vector<SpectralPeak> largest_peaks(const Spectrum& s, int count, double max_hz) {
  std::vector<SpectralPeak> c;
  const auto& a = s.amplitude;
  for (std::size_t k = 1; k + 1 < a.size(); ++k) {
    if (s.frequency_hz[k] > max_hz) break;
    if (a[k] > a[k - 1] && a[k] >= a[k + 1]) c.push_back({s.frequency_hz[k], a[k]});
  }
  const std::size_t n = std::min<std::size_t>(c.size(), static_cast<std::size_t>(count));
  std::partial_sort(
      c.begin(), c.begin() + static_cast<std::ptrdiff_t>(n), c.end(),
      [](const SpectralPeak& l, const SpectralPeak& r) { return l.amplitude > r.amplitude; });
  c.resize(n);
  return c;
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

// TSA angular resolution of shaft s: 2.8 x the highest order its gear metrics examine.
int tsa_samples_per_rev(const diag::Gearbox& gb, std::size_t s, const AnalyzeOptions& opt) {
  int zmax = 1;
  for (int g : gb.shafts()[s].gears)
    zmax = std::max(zmax, gb.gears()[static_cast<std::size_t>(g)].spec.teeth);
  const double top = opt.gear_metrics.mesh_harmonics * zmax + opt.gear_metrics.ser_sidebands;
  return static_cast<int>(
      std::clamp<std::size_t>(pow2_at_least(kOrderOversampling * top), 64, kMaxSamplesPerRev));
}

// P(X >= k) for X ~ Binomial(n, p).
double binomial_tail(int n, int k, double p) {
  double tail = 0;
  for (int i = k; i <= n; ++i) {
    tail += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) +
                     i * std::log(p) + (n - i) * std::log1p(-p));
  }
  return std::min(1.0, tail);
}

std::string fmt(double v, int prec = 3) {
  std::ostringstream o;
  o << std::setprecision(prec) << v;
  return o.str();
}

}  // namespace

void AnalyzeOptions::validate() const {
  require(welch_nperseg >= 8 && welch_nperseg <= (1u << 24), "welch_nperseg",
          std::to_string(welch_nperseg) + " is not in [8, 2^24]");
  require(kurtogram_max_level >= 1 && kurtogram_max_level <= 12, "kurtogram_max_level",
          std::to_string(kurtogram_max_level) + " is not in [1, 12]");
  require(tacho_pulses_per_rev >= 0 && tacho_pulses_per_rev <= 100000, "tacho_pulses_per_rev",
          std::to_string(tacho_pulses_per_rev) + " is not in [0, 100000]");
  require(tsa_min_revolutions >= 2, "tsa_min_revolutions",
          std::to_string(tsa_min_revolutions) + " is not >= 2");
  require(peaks_reported >= 0 && peaks_reported <= 100, "peaks_reported",
          std::to_string(peaks_reported) + " is not in [0, 100]");
  require(threads >= 0 && threads <= 256, "threads",
          std::to_string(threads) + " is not in [0, 256]");
  require(plot_points >= 16, "plot_points", std::to_string(plot_points) + " is not >= 16");
  require(envelope_plot_max_hz >= 0 && std::isfinite(envelope_plot_max_hz), "envelope_plot_max_hz",
          "must be finite and >= 0");
  sidebands.validate();
  require(gear_metrics.mesh_harmonics >= 1 && gear_metrics.mesh_harmonics <= 32,
          "gear_metrics.mesh_harmonics", "is not in [1, 32]");
  require(gear_metrics.ser_sidebands >= 1 && gear_metrics.ser_sidebands <= 64,
          "gear_metrics.ser_sidebands", "is not in [1, 64]");
  fault_bands.validate();
  bearing.validate();
  two_direction.validate();
  gear_damage.validate();
}

PlotTrace decimate_for_plot(std::span<const double> x, std::span<const double> y,
                            std::size_t max_points, Decimation mode) {
  if (x.size() != y.size()) {
    throw diag::InputError("decimate_for_plot: x and y differ in length");
  }
  if (max_points < 4) throw diag::InputError("decimate_for_plot: max_points: is not >= 4");
  PlotTrace t;
  if (x.size() <= max_points) {
    t.x.assign(x.begin(), x.end());
    t.y.assign(y.begin(), y.end());
    return t;
  }
  const bool max_only = mode == Decimation::kMax;
  const std::size_t buckets = max_only ? max_points : max_points / 2;
  t.x.reserve(2 * buckets);
  t.y.reserve(2 * buckets);
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t i0 = b * x.size() / buckets, i1 = (b + 1) * x.size() / buckets;
    std::size_t lo = i0, hi = i0;
    for (std::size_t i = i0; i < i1; ++i) {
      if (y[i] < y[lo]) lo = i;
      if (y[i] > y[hi]) hi = i;
    }
    if (max_only) {
      t.x.push_back(x[hi]);
      t.y.push_back(y[hi]);
      continue;
    }
    const std::size_t a = std::min(lo, hi), c = std::max(lo, hi);
    t.x.push_back(x[a]);
    t.y.push_back(y[a]);
    if (c != a) {
      t.x.push_back(x[c]);
      t.y.push_back(y[c]);
    }
  }
  return t;
}

AnalysisResult analyze_recording(const diag::Recording& rec, const diag::Gearbox* gb,
                                 const AnalyzeOptions& opt) {
  opt.validate();
  if (rec.signals.empty()) throw diag::InputError("analyze: the recording holds no signals");
  AnalysisResult r;
  for (const diag::Signal& s : rec.signals) {
    diag::validate(s, "analyze");
    r.duration_s = std::max(r.duration_s, s.duration_s());
  }
  const std::size_t plot_points = static_cast<std::size_t>(opt.plot_points);
  // Wall time per stage (AnalyzeOptions::timing; left out otherwise, so reports stay byte-equal).
  auto clock_start = std::chrono::steady_clock::now();
  const char* const kNextStage[][2] = {{"kinematics", "angle_plans"},
                                       {"angle_plans", "channels"},
                                       {"channels", "two_direction"},
                                       {"two_direction", "gear_damage"},
                                       {"gear_damage", "findings"}};
  if (opt.progress) opt.progress(gb ? "kinematics" : "channels");
  auto lap = [&](const char* stage) {
    if (opt.progress) {
      for (const auto& [done, next] : kNextStage) {
        if (std::string_view(done) == stage) opt.progress(next);
      }
    }
    if (!opt.timing) return;
    const auto now = std::chrono::steady_clock::now();
    r.timing_s[stage] += std::chrono::duration<double>(now - clock_start).count();
    clock_start = now;
  };

  ShaftKinematics kin;
  int input = -1;
  double input_hz = 0;
  if (gb) {
    r.gearbox_name = gb->name();
    kin = shaft_kinematics(rec, *gb, r.duration_s, opt, r.notes);
    r.shafts = kin.speeds;
    r.speed = kin.speed;
    if (!kin.speed.stationary) {
      r.notes.push_back("the speed varies over the record (" + fmt(kin.speed.min_rpm, 5) + " to " +
                        fmt(kin.speed.max_rpm, 5) +
                        " rpm): spectra and sidebands are drawn at the mean speed and smear; "
                        "the TSA and the damaged-shaft locator follow the shaft angles");
    }
    lap("kinematics");
    input = gb->input_shaft();
    r.input_shaft = gb->shafts()[static_cast<std::size_t>(input)].name;
    input_hz = kin.speeds[static_cast<std::size_t>(input)].speed_hz;
    const double scale = input_hz / gb->shaft_speed_hz(input);
    for (std::size_t j = 0; j < gb->meshes().size(); ++j) {
      const diag::Mesh& m = gb->meshes()[j];
      r.meshes.push_back({diag::mesh_name(*gb, static_cast<int>(j)), gb->gears()[m.driver].name,
                          gb->gears()[m.driven].name,
                          gb->mesh_frequency_hz(static_cast<int>(j)) * scale});
    }
  } else {
    r.notes.push_back("no gearbox description: unit-free indicators and spectra only");
  }

  // Highest order of interest in input-shaft orders: H mesh harmonics plus K sidebands.
  const int H = opt.sidebands.mesh_harmonics, K = opt.sidebands.sidebands;
  double max_input_order = 0;
  for (const auto& m : r.meshes) max_input_order = std::max(max_input_order, m.frequency_hz);
  if (gb) {
    double max_shaft = 0;
    for (const auto& s : r.shafts) max_shaft = std::max(max_shaft, s.speed_hz);
    max_input_order = (H * max_input_order + K * max_shaft) / input_hz;
  }

  // One angle plan per shaft for every channel of the common rate and length (resample.hpp: its
  // taps are computed once; applied per channel it gives the same bytes as the one-call form). A
  // channel of another rate or length, or a plan that cannot be built (too few revolutions: the
  // one-call form then says why in the channel's notes), resamples on its own.
  double plan_fs = 0;
  std::size_t plan_n = 0;
  for (const diag::Signal& sig : rec.signals) {
    if (sig.role == diag::Role::kVibration) {
      plan_fs = sig.fs_hz;
      plan_n = sig.samples.size();
      break;
    }
  }
  auto shares_plans = [&](const diag::Signal& sig) {
    return sig.fs_hz == plan_fs && sig.samples.size() == plan_n;
  };
  std::optional<AnglePlan> order_plan;
  std::vector<std::optional<AnglePlan>> tsa_plans(gb ? gb->shafts().size() : 0);
  if (gb && plan_n > 0) {
    try {
      ResampleOptions ro;
      ro.samples_per_rev = static_cast<int>(std::clamp<std::size_t>(
          pow2_at_least(kOrderOversampling * max_input_order), 64, kMaxSamplesPerRev));
      order_plan.emplace(
          make_angle_plan(kin.pulses_s[static_cast<std::size_t>(input)], plan_fs, plan_n, ro));
    } catch (const diag::InputError&) {
    }
    for (std::size_t s = 0; s < tsa_plans.size(); ++s) {
      const auto& pulses = kin.pulses_s[s];
      const int revs = pulses.size() > 1 ? static_cast<int>(pulses.size()) - 1 : 0;
      if (gb->shafts()[s].gears.empty() || revs < opt.tsa_min_revolutions) continue;
      try {
        TsaOptions to;
        to.samples_per_rev = tsa_samples_per_rev(*gb, s, opt);
        to.min_revolutions = opt.tsa_min_revolutions;
        tsa_plans[s].emplace(make_angle_plan(pulses, plan_fs, plan_n, to.resample_options()));
      } catch (const diag::InputError&) {
      }
    }
  }

  // Every sharing channel through each plan in one call (the kernel taps of an output sample are
  // computed once for all channels: the cost of resampling); the plans in parallel.
  const std::size_t nsig = rec.signals.size();
  auto through = [&](const AnglePlan& plan) {
    std::vector<std::span<const double>> xs;
    std::vector<std::size_t> which;
    for (std::size_t i = 0; i < nsig; ++i) {
      const diag::Signal& sig = rec.signals[i];
      const bool spectra = sig.role == diag::Role::kVibration || sig.role == diag::Role::kForce ||
                           sig.role == diag::Role::kDisplacement;
      if (spectra && shares_plans(sig) && sig.samples.size() >= 64) {
        xs.push_back(sig.samples);
        which.push_back(i);
      }
    }
    std::vector<std::optional<AngleResampled>> out(nsig);
    std::vector<AngleResampled> ar = resample_by_angle(xs, plan);
    for (std::size_t k = 0; k < which.size(); ++k) out[which[k]] = std::move(ar[k]);
    return out;
  };
  std::vector<std::optional<AngleResampled>> order_resampled;
  std::vector<std::vector<std::optional<AngleResampled>>> tsa_resampled(tsa_plans.size());
  {
    std::vector<std::function<void()>> jobs;
    if (order_plan) jobs.emplace_back([&] { order_resampled = through(*order_plan); });
    for (std::size_t s = 0; s < tsa_plans.size(); ++s) {
      if (tsa_plans[s]) jobs.emplace_back([&, s] { tsa_resampled[s] = through(*tsa_plans[s]); });
    }
    std::vector<std::exception_ptr> failed(jobs.size());
    std::atomic<std::size_t> next_job{0};
    auto run_jobs = [&] {
      for (std::size_t k = next_job++; k < jobs.size(); k = next_job++) {
        try {
          jobs[k]();
        } catch (...) {
          failed[k] = std::current_exception();
        }
      }
    };
    const std::size_t workers = std::min<std::size_t>(
        jobs.size(), opt.threads > 0 ? static_cast<std::size_t>(opt.threads)
                                     : std::max(1u, std::thread::hardware_concurrency()));
    {
      std::vector<std::jthread> pool;
      for (std::size_t t = 1; t < workers; ++t) pool.emplace_back(run_jobs);
      run_jobs();
    }
    for (const auto& e : failed) {
      if (e) std::rethrow_exception(e);
    }
  }
  lap("angle_plans");
  std::vector<Spectrum> full(rec.signals.size()), full_env(rec.signals.size());
  std::vector<bool> sensor(rec.signals.size(), false);
  for (std::size_t i : sensor_channels(rec)) sensor[i] = true;
  // A bearing is examined on the sensor channels at it, or on every sensor channel when none is.
  std::vector<bool> located(gb ? gb->bearings().size() : 0, false);
  for (std::size_t b = 0; b < located.size(); ++b)
    for (std::size_t i = 0; i < rec.signals.size(); ++i)
      located[b] = located[b] || (sensor[i] && rec.signals[i].location == gb->bearings()[b].name);
  // One channel's analysis; channels are independent, so they run in parallel (FFT plans are
  // shared and thread-safe, fft.hpp) and each writes only its own slots: same bytes whatever
  // the thread count.
  auto analyse = [&](std::size_t ci) -> ChannelAnalysis {
    const diag::Signal& sig = rec.signals[ci];
    ChannelAnalysis c;
    c.name = sig.name;
    c.unit = sig.unit;
    c.location = sig.location;
    c.direction = sig.direction;
    c.fs_hz = sig.fs_hz;
    c.samples = sig.samples.size();
    c.role = sig.role;
    c.shaft = sig.shaft;
    c.mesh = sig.mesh;
    // Spectra for what vibrates (sensors, and the simulator's mesh force and deflection); the
    // time indicators only for angles, speeds and other quantities.
    c.vibration = sig.role == diag::Role::kVibration || sig.role == diag::Role::kForce ||
                  sig.role == diag::Role::kDisplacement;
    c.sensor = sensor[ci];
    const std::span<const double> x(sig.samples);
    const Moments mo = moments(x);
    c.time = {mo.rms(), mo.peak(), mo.crest_factor(), mo.kurtosis(), mo.skewness()};
    if (!c.vibration) {
      return c;
    }
    if (x.size() < 64) {
      c.notes.push_back("fewer than 64 samples: no spectra");
      return c;
    }
    const double fs = sig.fs_hz, nyq = 0.5 * fs;

    // ---- spectra ----
    SpectrumOptions so;
    so.fs_hz = fs;
    so.window = opt.spectrum_window;
    so.remove_mean = true;
    Spectrum& sp = full[ci];
    sp = amplitude_spectrum(x, so);
    c.spectrum_resolution_hz = sp.resolution_hz;
    c.spectrum_enbw_hz = sp.enbw_hz;
    c.spectrum_peaks = largest_peaks(sp, opt.peaks_reported, nyq);
    c.spectrum = decimate_for_plot(sp.frequency_hz, sp.amplitude, plot_points, Decimation::kMax);
    WelchOptions wo;
    wo.fs_hz = fs;
    wo.nperseg = std::min(opt.welch_nperseg, pow2_at_most(x.size()));
    const Psd psd = welch(x, wo);
    c.psd = decimate_for_plot(psd.frequency_hz, psd.value, plot_points, Decimation::kMax);
    c.psd_resolution_hz = psd.resolution_hz;
    c.psd_segments = psd.segments;

    // ---- envelope in the kurtogram's band ----
    EnvelopeSpectrumOptions eo;
    eo.fs_hz = fs;
    const int level =
        std::min(opt.kurtogram_max_level,
                 static_cast<int>(std::floor(std::log2(static_cast<double>(x.size())))) - 7);
    if (level >= 1) {
      KurtogramOptions ko;
      ko.fs_hz = fs;
      ko.max_level = level;
      const Kurtogram kg = fast_kurtogram(x, ko);
      c.kurtogram_level = kg.level;
      c.kurtogram_kurtosis = kg.kurtosis;
      eo.band_low_hz = std::max(0.0, kg.low_hz());
      eo.band_high_hz = std::min(nyq, kg.high_hz());
    } else {
      c.notes.push_back("record too short for the kurtogram: envelope of the whole band");
    }
    c.envelope_low_hz = eo.band_low_hz;
    c.envelope_high_hz = eo.band_high_hz == 0 ? nyq : eo.band_high_hz;
    full_env[ci] = envelope_spectrum(x, eo);
    const Spectrum& env = full_env[ci];
    double env_max = opt.envelope_plot_max_hz;
    if (env_max == 0) {
      env_max = 1000.0;
      if (gb && !gb->bearings().empty()) {
        double top = 0;
        for (const auto& b : gb->bearings()) {
          const int s = gb->shaft_index(b.shaft);
          if (s < 0) continue;
          const auto f = bearing_frequencies(b, kin.speeds[static_cast<std::size_t>(s)].speed_hz);
          top = std::max({top, f.bpfi_hz, f.bpfo_hz, f.ball_fault_hz});
        }
        if (top > 0) env_max = 5 * top;
      }
    }
    env_max = std::min(env_max, nyq);
    c.envelope_peaks = largest_peaks(env, opt.peaks_reported, env_max);
    c.envelope = slice_for_plot(env.frequency_hz, env.amplitude, 0, env_max, plot_points);

    if (gb && c.sensor && !gb->bearings().empty()) {
      // ---- bearings: diagnose_bearings once per shaft, on the bearings this channel sees ----
      std::map<int, std::vector<diag::BearingSpec>> by_shaft;
      for (std::size_t b = 0; b < located.size(); ++b) {
        const diag::BearingSpec& spec = gb->bearings()[b];
        const int s = gb->shaft_index(spec.shaft);
        if (s >= 0 && (!located[b] || c.location == spec.name)) by_shaft[s].push_back(spec);
      }
      std::map<std::string, std::pair<const BearingStatus*, const BearingDiagnosis*>> status;
      std::vector<BearingDiagnosis> diagnoses;
      diagnoses.reserve(by_shaft.size());
      BearingDiagnosisOptions bo = opt.bearing;
      bo.kurtogram_max_level =
          std::min(bo.kurtogram_max_level,
                   static_cast<int>(std::floor(std::log2(static_cast<double>(x.size())))) - 7);
      for (const auto& [s, specs] : by_shaft) {
        std::string names;
        for (const auto& b : specs) names += (names.empty() ? "" : ", ") + b.name;
        if (bo.kurtogram_max_level < 1) {
          c.notes.push_back("bearing diagnosis (" + names +
                            ") skipped: " + std::to_string(x.size()) + " samples, fewer than 2^8");
          continue;
        }
        try {
          diagnoses.push_back(
              diagnose_bearings(sig, kin.speeds[static_cast<std::size_t>(s)].speed_hz, specs, bo));
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
          ba.frequencies =
              bearing_frequencies(spec, kin.speeds[static_cast<std::size_t>(s)].speed_hz);
          ba.bands = bearing_fault_bands(ba.frequencies, opt.fault_bands);
          ba.metrics = fault_band_metrics(ev, ba.bands, SpectrumScale::kAmplitude);
          if (const auto it = status.find(spec.name); it != status.end()) {
            ba.diagnosed = true;
            ba.diagnosis = *it->second.first;
            ba.band_centre_hz = it->second.second->band_centre_hz;
            ba.band_width_hz = it->second.second->band_width_hz;
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
    if (gb) {
      const SpectrumView view{sp.frequency_hz, sp.amplitude};
      // ---- meshes and sidebands ----
      for (std::size_t j = 0; j < gb->meshes().size(); ++j) {
        const diag::Mesh& m = gb->meshes()[j];
        const int sa = gb->shaft_of_gear(m.driver), sb = gb->shaft_of_gear(m.driven);
        std::vector<ShaftCandidate> cand{{gb->shafts()[static_cast<std::size_t>(sa)].name,
                                          kin.speeds[static_cast<std::size_t>(sa)].speed_hz},
                                         {gb->shafts()[static_cast<std::size_t>(sb)].name,
                                          kin.speeds[static_cast<std::size_t>(sb)].speed_hz}};
        MeshAnalysis ma;
        ma.mesh = static_cast<int>(j);
        ma.name = r.meshes[j].name;
        ma.mesh_hz = r.meshes[j].frequency_hz;
        // The rest of the gearbox: another mesh's harmonics and the combination tones of two
        // meshes are not sidebands of a shaft (sidebands.hpp).
        SidebandContext context;
        for (std::size_t i = 0; i < r.meshes.size(); ++i) {
          if (i != j) context.other_mesh_hz.push_back(r.meshes[i].frequency_hz);
        }
        ma.sidebands = analyse_sidebands(view, ma.mesh_hz, cand, opt.sidebands, context);
        const double span = (K + 2) * std::max(cand[0].frequency_hz, cand[1].frequency_hz);
        ma.zoom = slice_for_plot(sp.frequency_hz, sp.amplitude, ma.mesh_hz - span,
                                 ma.mesh_hz + span, plot_points);
        c.meshes.push_back(std::move(ma));
      }
      // ---- order spectrum (input-shaft orders) ----
      try {
        ResampleOptions ro;
        ro.samples_per_rev = static_cast<int>(std::clamp<std::size_t>(
            pow2_at_least(kOrderOversampling * max_input_order), 64, kMaxSamplesPerRev));
        const OrderSpectrum os =
            !order_resampled.empty() && order_resampled[ci]
                ? order_spectrum(*order_resampled[ci])
                : order_spectrum(
                      resample_by_angle(x, fs, kin.pulses_s[static_cast<std::size_t>(input)], ro));
        c.order_spectrum =
            slice_for_plot(os.order, os.amplitude, 0,
                           std::min(1.2 * max_input_order, os.order.back()), plot_points);
      } catch (const diag::InputError& e) {
        c.notes.push_back(std::string("order spectrum skipped: ") + e.what());
      }
      // ---- TSA per shaft ----
      for (std::size_t s = 0; s < gb->shafts().size(); ++s) {
        const diag::Shaft& shaft = gb->shafts()[s];
        if (shaft.gears.empty()) continue;
        ShaftTsaAnalysis ta;
        ta.shaft = shaft.name;
        std::vector<int> orders;
        for (int g : shaft.gears)
          orders.push_back(gb->gears()[static_cast<std::size_t>(g)].spec.teeth);
        const int spr = tsa_samples_per_rev(*gb, s, opt);
        const auto& pulses = kin.pulses_s[s];
        const int revs = pulses.size() > 1 ? static_cast<int>(pulses.size()) - 1 : 0;
        if (revs < opt.tsa_min_revolutions) {
          ta.note = std::to_string(revs) + " revolutions in the record, fewer than " +
                    std::to_string(opt.tsa_min_revolutions) + ": no TSA";
          c.tsa.push_back(std::move(ta));
          continue;
        }
        try {
          TsaOptions to;
          to.samples_per_rev = spr;
          to.min_revolutions = opt.tsa_min_revolutions;
          const Tsa t = !tsa_resampled[s].empty() && tsa_resampled[s][ci]
                            ? tsa(*tsa_resampled[s][ci], opt.tsa_min_revolutions)
                            : tsa(x, fs, pulses, to);
          ta.revolutions = t.revolutions;
          ta.samples_per_rev = t.samples_per_rev;
          ta.tsa = t.samples;
          ta.regular = tsa_regular(t, orders);
          ta.residual = tsa_residual(t, orders);
          ta.difference = tsa_difference(t, orders);
          ta.computed = true;
          for (int g : shaft.gears) {
            const auto& ge = gb->gears()[static_cast<std::size_t>(g)];
            GearMetricOptions gm = opt.gear_metrics;
            gm.mesh_order = ge.spec.teeth;
            gm.ser_sidebands = std::min(gm.ser_sidebands, ge.spec.teeth - 1);
            gm.mesh_harmonics = std::min(
                gm.mesh_harmonics, (spr / 2 - 1 - gm.ser_sidebands) / std::max(1, gm.mesh_order));
            GearMetricsRow row;
            row.gear = ge.name;
            row.teeth = ge.spec.teeth;
            if (gm.ser_sidebands < 1 || gm.mesh_harmonics < 1) {
              ta.note = "gear " + ge.name + ": too few teeth or samples for the gear metrics";
              continue;
            }
            row.indicators = gear_indicators({ta.tsa, ta.difference, ta.regular, ta.residual}, gm);
            ta.gears.push_back(row);
          }
        } catch (const diag::InputError& e) {
          ta.note = std::string("TSA skipped: ") + e.what();
        }
        c.tsa.push_back(std::move(ta));
      }
    }
    return c;
  };
  const std::size_t nc = rec.signals.size();
  r.channels.resize(nc);
  std::vector<std::exception_ptr> errors(nc);
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t ci = next++; ci < nc; ci = next++) {
      try {
        r.channels[ci] = analyse(ci);
      } catch (...) {
        errors[ci] = std::current_exception();
      }
    }
  };
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t threads =
      std::min<std::size_t>(nc, opt.threads > 0 ? static_cast<std::size_t>(opt.threads) : hw);
  {
    std::vector<std::jthread> pool;
    for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
  }
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);  // the first failing channel, in channel order
  }
  lap("channels");

  if (gb) {
    // ---- two directions ----
    for (std::size_t ai = 0; ai < r.channels.size(); ++ai) {
      const ChannelAnalysis& a = r.channels[ai];
      if (a.direction != diag::Direction::kAlongLoa || full[ai].amplitude.empty()) continue;
      // The partner: the normal-LOA sensor at the same location following the same mesh (the
      // channel contract's location and mesh; no name is parsed); without a mesh on either, the
      // only normal-LOA sensor at that location.
      int ni = -1, same_location = -1, count = 0;
      for (std::size_t k = 0; k < r.channels.size(); ++k) {
        const ChannelAnalysis& n = r.channels[k];
        if (n.direction != diag::Direction::kNormalLoa || n.location != a.location ||
            full[k].amplitude.empty() || n.fs_hz != a.fs_hz || n.samples != a.samples) {
          continue;
        }
        if (!a.mesh.empty() && n.mesh == a.mesh) ni = static_cast<int>(k);
        same_location = static_cast<int>(k);
        ++count;
      }
      if (ni < 0 && count == 1 && (a.mesh.empty() || r.channels[same_location].mesh.empty())) {
        ni = same_location;
      }
      if (ni < 0) {
        r.notes.push_back("two directions: no normal_loa partner for '" + a.name + "'");
        continue;
      }
      std::vector<std::size_t> meshes;
      for (int j : diag::sensor_meshes(rec.signals[ai], *gb)) {
        meshes.push_back(static_cast<std::size_t>(j));
      }
      if (meshes.empty()) {
        for (std::size_t j = 0; j < r.meshes.size(); ++j) meshes.push_back(j);
      }
      const Spectrum& sa = full[ai];
      const Spectrum& sn = full[static_cast<std::size_t>(ni)];
      for (std::size_t j : meshes) {
        TwoDirectionRow row;
        row.location = a.location;
        row.along_channel = a.name;
        row.normal_channel = r.channels[static_cast<std::size_t>(ni)].name;
        row.mesh = r.meshes[j].name;
        row.comparison = compare_two_directions(
            {sa.frequency_hz, sa.amplitude}, {sn.frequency_hz, sn.amplitude},
            sa.enbw_hz / sa.resolution_hz, r.meshes[j].frequency_hz, opt.two_direction);
        r.two_direction.push_back(std::move(row));
      }
    }

    lap("two_direction");
    // ---- which shaft carries a damaged gear ----
    bool has_gear_shaft = false;
    for (const diag::Shaft& sh : gb->shafts()) has_gear_shaft |= !sh.gears.empty();
    if (has_gear_shaft) {
      const int ref = kin.reference_shaft >= 0 ? kin.reference_shaft : input;
      try {
        r.gear_damage =
            locate_gear_damage(rec, *gb, gb->shafts()[static_cast<std::size_t>(ref)].name,
                               kin.pulses_s[static_cast<std::size_t>(ref)], opt.gear_damage);
        r.gear_damage_angles = kin.speed.source;
      } catch (const diag::InputError& e) {
        r.notes.push_back(std::string("damaged-shaft location skipped: ") + e.what());
      }
    }
    if (r.gear_damage) {
      for (const GearDamageFinding& g : r.gear_damage->findings) {
        AnalysisFinding f;
        f.kind = "gear_damage";
        f.shaft = g.shaft;
        f.gears = g.gears;
        f.channel = g.channel;
        f.confidence = g.confidence;
        f.note =
            "a localised fault once per revolution of " + g.shaft + " (TSA per shaft, " +
            r.gear_damage->status + "): " + g.note +
            (r.gear_damage_angles == "nominal" ? " (shaft angles from the nominal speed: no tacho)"
             : r.gear_damage_angles == "vibration"
                 ? " (shaft angles from the vibration's mesh line: no tacho)"
                 : "");
        r.findings.push_back(std::move(f));
      }
    }

    lap("gear_damage");
    // ---- findings: sideband families (low confidence: a vote over channels) ----
    for (std::size_t j = 0; j < r.meshes.size(); ++j) {
      std::map<std::string, int> votes;
      std::map<std::string, std::pair<double, std::string>> best;  // score, channel
      std::map<std::string, double> best_mean_db;  // the best channel's mean line prominence
      int analysed = 0;
      for (const auto& c : r.channels) {
        if (!c.sensor || j >= c.meshes.size()) continue;
        const SidebandAnalysis& sb = c.meshes[j].sidebands;
        if (sb.mesh.empty() || !sb.mesh.front().valid) continue;
        ++analysed;
        if (sb.status != SidebandStatus::kPointed) continue;
        const ShaftSidebands& w = sb.shafts[static_cast<std::size_t>(sb.pointed)];
        ++votes[w.name];
        if (w.score_db > best[w.name].first) {
          best[w.name] = {w.score_db, c.name};
          best_mean_db[w.name] = w.score_db / std::max(1, w.detected);
        }
      }
      std::string winner;
      int top = 0, second = 0;
      for (const auto& [name, v] : votes) {
        if (v > top) {
          second = top;
          top = v;
          winner = name;
        } else {
          second = std::max(second, v);
        }
      }
      if (top == 0 || top == second) continue;
      // A quorum: `top` channels of `analysed` pointing at one shaft must be unlikely for
      // channels that point at random with probability kFalsePointing each (binomial tail <=
      // kQuorumP): 1 of 2 passes, 2 of 28 does not, 4 of 28 does. Why 5 %: on the healthy
      // two-stage box with 4 m/s^2 noise (2000 rpm, seed 5) 2 of 28 channels pointed at the
      // input; the channels of one rigid shaft are not independent, so a small count is no
      // evidence. (With 1 %, that healthy box was a finding.)
      constexpr double kFalsePointing = 0.05, kQuorumP = 0.1;
      if (binomial_tail(analysed, top, kFalsePointing) > kQuorumP) {
        r.notes.push_back("sidebands of mesh " + r.meshes[j].name + " point at " + winner +
                          " in only " + std::to_string(top) + " of " + std::to_string(analysed) +
                          " channels: no finding");
        continue;
      }
      AnalysisFinding f;
      f.kind = "gear_sidebands";
      f.shaft = winner;
      const diag::Mesh& m = gb->meshes()[j];
      for (int g : {m.driver, m.driven}) {
        if (gb->shafts()[static_cast<std::size_t>(gb->shaft_of_gear(g))].name == winner) {
          f.gears.push_back(gb->gears()[static_cast<std::size_t>(g)].name);
        }
      }
      f.frequency_hz = r.meshes[j].frequency_hz;
      f.channel = best[winner].second;
      f.confidence = 0.2 + 0.3 * top / analysed;
      // The mean prominence of the best channel's detected lines; at the detector's cap the
      // spectrum has no noise floor (a noise-free simulation): said so, not a number.
      const double mean_db = best_mean_db[winner];
      const std::string prominence = mean_db >= opt.sidebands.dynamic_range_db
                                         ? "at the " + fmt(opt.sidebands.dynamic_range_db) +
                                               " dB dynamic-range cap: no noise floor"
                                         : fmt(mean_db, 3) + " dB over the local floor on average";
      f.note = "sidebands of mesh " + r.meshes[j].name + " (" + fmt(f.frequency_hz, 5) +
               " Hz) spaced at shaft " + winner + "'s rotation in " + std::to_string(top) + " of " +
               std::to_string(analysed) + " channels (best " + f.channel + ", " + prominence +
               "): a local defect or eccentricity of " +
               (f.gears.empty() ? winner : f.gears.front()) + " modulates the mesh";
      r.findings.push_back(std::move(f));
    }
    // ---- findings: bearings ----
    for (const diag::BearingSpec& b : gb->bearings()) {
      std::map<BearingFault, int> votes;
      std::map<BearingFault, std::pair<double, std::string>> best;
      std::map<BearingFault, double> freq;
      int analysed = 0;
      for (const auto& c : r.channels) {
        for (const auto& ba : c.bearings) {
          if (ba.bearing != b.name || !ba.diagnosed) continue;
          ++analysed;
          const BearingStatus& st = ba.diagnosis;
          if (st.status != BearingDecisionStatus::kFault) continue;
          ++votes[st.fault];
          for (const auto& fam : st.band_decision.families) {
            if (fam.fault != st.fault) continue;
            freq[fam.fault] = fam.fundamental_hz;
            auto& [score, channel] = best.try_emplace(fam.fault, -kInf, "").first->second;
            if (fam.score_db > score) score = fam.score_db, channel = c.name;
          }
        }
      }
      BearingFault winner = BearingFault::kNone;
      int top = 0, second = 0;
      for (const auto& [fault, v] : votes) {
        if (v > top) {
          second = top;
          top = v;
          winner = fault;
        } else {
          second = std::max(second, v);
        }
      }
      if (top == 0 || top == second) continue;
      AnalysisFinding f;
      f.kind = "bearing";
      f.bearing = b.name;
      f.shaft = b.shaft;
      f.fault = finding_name(winner);  // the findings' names: rolling_element, not ball
      f.frequency_hz = freq[winner];
      f.channel = best[winner].second;
      f.confidence = 0.3 + 0.4 * top / analysed;
      f.note = std::string(to_string(winner)) + " fault lines at " + fmt(f.frequency_hz, 5) +
               " Hz and harmonics in the prewhitened squared envelope spectrum (kurtogram band "
               "and whole band agree) of " +
               std::to_string(top) + " of " + std::to_string(analysed) + " channels (best " +
               f.channel + ", score " + fmt(best[winner].first, 3) + " dB)";
      r.findings.push_back(std::move(f));
    }
    std::stable_sort(r.findings.begin(), r.findings.end(),
                     [](const AnalysisFinding& a, const AnalysisFinding& b) {
                       return a.confidence > b.confidence;
                     });
  }
  lap("findings");
  return r;
}

void BaselineComparisonOptions::validate() const {
  features.validate();
  baseline.validate();
  if (segments_per_recording < 1 || segments_per_recording > 64)
    throw diag::InputError("score_against_baseline: segments_per_recording: " +
                           std::to_string(segments_per_recording) + " is not in [1, 64]");
}

namespace {

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "none" : s;
}

// Samples [k n / parts, (k + 1) n / parts) of a channel, as a signal of its own.
diag::Signal part_of(const diag::Signal& s, std::size_t k, std::size_t parts) {
  diag::Signal p;
  p.name = s.name;
  p.fs_hz = s.fs_hz;
  const std::size_t n = s.samples.size();
  p.samples.assign(s.samples.begin() + static_cast<std::ptrdiff_t>(k * n / parts),
                   s.samples.begin() + static_cast<std::ptrdiff_t>((k + 1) * n / parts));
  return p;
}

}  // namespace

AnalysisBaseline score_against_baseline(const diag::Recording& rec,
                                        std::span<const diag::Recording> baseline,
                                        const BaselineComparisonOptions& opt,
                                        std::span<const std::string> names) {
  opt.validate();
  const std::string w = "score_against_baseline";
  if (baseline.empty()) throw diag::InputError(w + ": baseline: no recording given");
  if (!names.empty() && names.size() != baseline.size())
    throw diag::InputError(w + ": names: " + std::to_string(names.size()) + " names for " +
                           std::to_string(baseline.size()) + " baseline recordings");
  AnalysisBaseline out;
  for (std::size_t i = 0; i < baseline.size(); ++i)
    out.recordings.push_back(names.empty() ? "baseline recording " + std::to_string(i + 1)
                                           : names[i]);

  // ---- channels: the recording's sensor channels found in every baseline recording ----
  std::vector<const diag::Signal*> channels;
  std::vector<std::string> sensor_names;
  for (std::size_t idx : sensor_channels(rec)) sensor_names.push_back(rec.signals[idx].name);
  if (sensor_names.empty())
    throw diag::InputError(w + ": the recording holds no vibration channel to compare");
  for (std::size_t i = 0; i < baseline.size(); ++i) {
    bool shared = false;
    for (const auto& n : sensor_names) shared |= baseline[i].find(n) != nullptr;
    if (!shared) {
      std::vector<std::string> theirs;
      for (const auto& s : baseline[i].signals) theirs.push_back(s.name);
      throw diag::InputError(out.recordings[i] +
                             ": no channel in common with the recording "
                             "(baseline channels: " +
                             joined(theirs) + "; the recording's: " + joined(sensor_names) + ")");
    }
  }
  for (std::size_t idx : sensor_channels(rec)) {
    const diag::Signal& s = rec.signals[idx];
    std::string missing_in;
    for (std::size_t i = 0; i < baseline.size(); ++i) {
      const diag::Signal* b = baseline[i].find(s.name);
      if (b == nullptr) {
        missing_in += (missing_in.empty() ? "" : ", ") + out.recordings[i];
        continue;
      }
      if (std::abs(b->fs_hz - s.fs_hz) > 1e-9 * s.fs_hz)
        throw diag::InputError(out.recordings[i] + ": channel " + s.name + ": fs_hz " +
                               fmt(b->fs_hz, 10) + " differs from the recording's " +
                               fmt(s.fs_hz, 10) +
                               " Hz (the features compare bands at fractions of fs: record the "
                               "baseline at the recording's rate)");
    }
    if (!missing_in.empty()) {
      out.notes.push_back("channel " + s.name + " is not in " + missing_in +
                          ": left out of the comparison");
      continue;
    }
    channels.push_back(&s);
  }

  // ---- parts per baseline recording: every part holds 4 nperseg samples of each channel ----
  const std::size_t min_part = 4 * opt.features.nperseg;
  std::vector<std::size_t> parts(baseline.size());
  for (std::size_t i = 0; i < baseline.size(); ++i) {
    std::size_t shortest = std::numeric_limits<std::size_t>::max();
    for (const diag::Signal* s : channels)
      shortest = std::min(shortest, baseline[i].find(s->name)->samples.size());
    parts[i] = std::clamp<std::size_t>(shortest / min_part, 1,
                                       static_cast<std::size_t>(opt.segments_per_recording));
    if (parts[i] < static_cast<std::size_t>(opt.segments_per_recording))
      out.notes.push_back(out.recordings[i] + ": " + std::to_string(shortest) +
                          " samples, cut into " + std::to_string(parts[i]) + " part" +
                          (parts[i] == 1 ? "" : "s") + " instead of " +
                          std::to_string(opt.segments_per_recording) + " (a part needs " +
                          std::to_string(min_part) + ")");
  }

  // ---- features; a channel whose features fail anywhere is left out ----
  std::vector<FeatureSet> healthy(std::accumulate(parts.begin(), parts.end(), std::size_t{0}));
  FeatureSet scored;
  std::vector<std::string> reasons;
  for (const diag::Signal* s : channels) {
    try {
      FeatureSet whole = prefixed(s->name, baseline_features(*s, opt.features));
      std::vector<FeatureSet> per_part;
      for (std::size_t i = 0; i < baseline.size(); ++i) {
        const diag::Signal& b = *baseline[i].find(s->name);
        for (std::size_t k = 0; k < parts[i]; ++k) {
          try {
            per_part.push_back(
                prefixed(s->name, baseline_features(part_of(b, k, parts[i]), opt.features)));
          } catch (const diag::InputError& e) {
            throw diag::InputError(out.recordings[i] + ": " + e.what());
          }
        }
      }
      scored.merge(whole);
      for (std::size_t j = 0; j < healthy.size(); ++j) healthy[j].merge(per_part[j]);
      out.channels.push_back(s->name);
    } catch (const diag::InputError& e) {
      reasons.push_back(e.what());
      out.notes.push_back("channel " + s->name + " left out of the comparison: " + e.what());
    }
  }
  if (out.channels.empty())
    throw diag::InputError(w + ": no channel left to compare with the baseline (" +
                           joined(out.notes) + ")");
  if (healthy.size() < opt.baseline.min_samples)
    throw diag::InputError(
        w + ": baseline: " + std::to_string(baseline.size()) + " recordings give " +
        std::to_string(healthy.size()) + " samples, fewer than min_samples = " +
        std::to_string(opt.baseline.min_samples) + ": give more or longer baseline recordings");
  out.samples = healthy.size();

  // ---- fit and score ----
  const Baseline fitted = Baseline::fit(healthy, opt.baseline);
  const Baseline::Score score = fitted.score(scored);
  out.anomaly_score = score.anomaly_score;
  out.threshold = score.threshold;
  out.alarm = score.alarm;
  for (const auto& [name, st] : fitted.features())
    out.deviations.push_back(
        {name, scored.at(name), st.centre, st.spread, score.deviation.at(name)});
  std::stable_sort(out.deviations.begin(), out.deviations.end(),
                   [](const AnalysisBaselineDeviation& a, const AnalysisBaselineDeviation& b) {
                     return std::abs(a.z) > std::abs(b.z);
                   });
  return out;
}

std::map<std::string, double> features(const AnalysisResult& r) {
  std::map<std::string, double> f;
  auto put = [&f](const std::string& k, double v) {
    if (std::isfinite(v)) f[k] = v;
  };
  for (const auto& c : r.channels) {
    const std::string p = c.name + "/";
    put(p + "rms", c.time.rms);
    put(p + "peak", c.time.peak);
    put(p + "crest_factor", c.time.crest_factor);
    put(p + "kurtosis", c.time.kurtosis);
    put(p + "skewness", c.time.skewness);
    for (const auto& m : c.meshes) {
      for (const auto& l : m.sidebands.mesh) {
        if (l.valid) {
          put(p + "mesh/" + m.name + "/h" + std::to_string(&l - m.sidebands.mesh.data() + 1) +
                  "_amplitude",
              l.amplitude);
        }
      }
    }
    for (const auto& t : c.tsa) {
      for (const auto& g : t.gears) {
        const std::string q = p + "tsa/" + t.shaft + "/" + g.gear + "/";
        const GearIndicators& i = g.indicators;
        put(q + "fm0", i.fm0);
        put(q + "fm4", i.fm4);
        put(q + "m6a", i.m6a);
        put(q + "m8a", i.m8a);
        put(q + "na4", i.na4);
        put(q + "er", i.er);
        put(q + "ser", i.ser);
        put(q + "slf", i.slf);
        put(q + "si", i.si);
      }
    }
  }
  for (const auto& t : r.two_direction) {
    put("two_direction/" + t.location + "/" + t.mesh + "/normal_to_along_db",
        t.comparison.normal_to_along_db);
  }
  if (r.gear_damage) {
    for (const auto& s : r.gear_damage->shafts) {
      const std::string q = "gear_damage/" + s.shaft + "/";
      put(q + "score", s.score);
      put(q + "snr", s.snr);
      put(q + "level", s.level);
    }
  }
  return f;
}

namespace {

nlohmann::json peaks_json(const std::vector<SpectralPeak>& p) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& k : p)
    a.push_back({{"frequency_hz", k.frequency_hz}, {"amplitude", k.amplitude}});
  return a;
}

const char* to_string(SidebandStatus s) {
  switch (s) {
    case SidebandStatus::kNoSidebands:
      return "no_sidebands";
    case SidebandStatus::kPointed:
      return "pointed";
    case SidebandStatus::kAmbiguous:
      return "ambiguous";
  }
  return "unknown";
}

}  // namespace

nlohmann::json to_json(const AnalysisResult& r) {
  using nlohmann::json;
  json j;
  j["format"] = "geardiag-analysis";
  j["format_version"] = 1;
  j["gearbox"] = r.gearbox_name.empty() ? json(nullptr) : json(r.gearbox_name);
  j["input_shaft"] = r.input_shaft.empty() ? json(nullptr) : json(r.input_shaft);
  j["duration_s"] = r.duration_s;
  if (!r.timing_s.empty()) j["timing_s"] = r.timing_s;
  if (!r.speed.source.empty()) {
    j["speed"] = {{"source", r.speed.source},     {"reference_shaft", r.speed.reference_shaft},
                  {"line", r.speed.line},         {"nominal_rpm", r.speed.nominal_rpm},
                  {"mean_rpm", r.speed.mean_rpm}, {"min_rpm", r.speed.min_rpm},
                  {"max_rpm", r.speed.max_rpm},   {"stationary", r.speed.stationary}};
  }
  j["shafts"] = json::array();
  for (const auto& s : r.shafts) {
    j["shafts"].push_back({{"shaft", s.shaft},
                           {"speed_hz", s.speed_hz},
                           {"speed_rpm", s.speed_hz * 60},
                           {"source", s.source},
                           {"tacho_repairs", s.tacho_repairs}});
  }
  j["meshes"] = json::array();
  for (const auto& m : r.meshes) {
    j["meshes"].push_back({{"mesh", m.name},
                           {"driver", m.driver},
                           {"driven", m.driven},
                           {"frequency_hz", m.frequency_hz}});
  }
  j["channels"] = json::array();
  for (const auto& c : r.channels) {
    json cj{{"name", c.name},
            {"unit", c.unit},
            {"direction", std::string(diag::to_string(c.direction))},
            {"location", c.location},
            {"role", std::string(diag::to_string(c.role))},
            {"shaft", c.shaft},
            {"mesh", c.mesh},
            {"fs_hz", c.fs_hz},
            {"samples", c.samples},
            {"vibration", c.vibration},
            {"sensor", c.sensor},
            {"indicators",
             {{"rms", c.time.rms},
              {"peak", c.time.peak},
              {"crest_factor", c.time.crest_factor},
              {"kurtosis", c.time.kurtosis},
              {"skewness", c.time.skewness}}}};
    if (c.vibration && !c.spectrum.x.empty()) {
      cj["spectrum"] = {{"resolution_hz", c.spectrum_resolution_hz},
                        {"enbw_hz", c.spectrum_enbw_hz},
                        {"peaks", peaks_json(c.spectrum_peaks)}};
      cj["psd"] = {{"resolution_hz", c.psd_resolution_hz}, {"segments", c.psd_segments}};
      cj["envelope"] = {{"band_low_hz", c.envelope_low_hz},
                        {"band_high_hz", c.envelope_high_hz},
                        {"kurtogram_level", c.kurtogram_level},
                        {"kurtogram_kurtosis", c.kurtogram_kurtosis},
                        {"peaks", peaks_json(c.envelope_peaks)}};
    }
    json meshes = json::array();
    for (const auto& m : c.meshes) {
      json h = json::array();
      int k = 1;
      for (const auto& l : m.sidebands.mesh) {
        h.push_back({{"harmonic", k++},
                     {"frequency_hz", l.frequency_hz},
                     {"amplitude", l.amplitude},
                     {"prominence_db", l.prominence_db},
                     {"valid", l.valid}});
      }
      json shafts = json::array();
      for (const auto& s : m.sidebands.shafts) {
        shafts.push_back({{"shaft", s.name},
                          {"frequency_hz", s.frequency_hz},
                          {"detected", s.detected},
                          {"score_db", s.score_db},
                          {"passes", s.passes}});
      }
      const bool pointed = m.sidebands.status == SidebandStatus::kPointed;
      meshes.push_back(
          {{"mesh", m.name},
           {"frequency_hz", m.mesh_hz},
           {"harmonics", h},
           {"sidebands",
            {{"status", to_string(m.sidebands.status)},
             {"pointed_shaft",
              pointed ? json(m.sidebands.shafts[static_cast<std::size_t>(m.sidebands.pointed)].name)
                      : json(nullptr)},
             {"shafts", shafts}}}});
    }
    cj["meshes"] = meshes;
    json tsa = json::array();
    for (const auto& t : c.tsa) {
      json gears = json::array();
      for (const auto& g : t.gears) {
        const GearIndicators& i = g.indicators;
        gears.push_back({{"gear", g.gear},
                         {"teeth", g.teeth},
                         {"rms", i.rms},
                         {"peak", i.peak},
                         {"crest_factor", i.crest_factor},
                         {"kurtosis", i.kurtosis},
                         {"fm0", i.fm0},
                         {"fm4", i.fm4},
                         {"m6a", i.m6a},
                         {"m8a", i.m8a},
                         {"na4", i.na4},
                         {"er", i.er},
                         {"ser", i.ser},
                         {"slf", i.slf},
                         {"si", i.si}});
      }
      tsa.push_back({{"shaft", t.shaft},
                     {"computed", t.computed},
                     {"note", t.note},
                     {"revolutions", t.revolutions},
                     {"samples_per_rev", t.samples_per_rev},
                     {"gears", gears}});
    }
    cj["tsa"] = tsa;
    json bearings = json::array();
    for (const auto& b : c.bearings) {
      const BearingFrequencies& f = b.frequencies;
      json bands = json::array();
      for (std::size_t k = 0; k < b.bands.size(); ++k) {
        const BandMetrics& m = b.metrics.bands[k];
        bands.push_back({{"label", b.bands[k].label},
                         {"centre_hz", b.bands[k].centre_hz},
                         {"low_hz", b.bands[k].low_hz},
                         {"high_hz", b.bands[k].high_hz},
                         {"peak", m.peak_value},
                         {"peak_frequency_hz", m.peak_frequency_hz},
                         {"energy", m.energy},
                         {"energy_fraction", m.energy_fraction}});
      }
      auto families = [](const BearingDecision& d) {
        json fams = json::array();
        for (const auto& fam : d.families) {
          // -- bearing evidence (h/bearings): lines, sidebands and modulation per family --
          json line_db = json::array();
          for (const auto& m : fam.lines) line_db.push_back(m.valid ? m.prominence_db : 0.0);
          fams.push_back({{"fault", to_string(fam.fault)},
                          {"fundamental_hz", fam.fundamental_hz},
                          {"detected", fam.detected},
                          {"line_db", line_db},
                          {"sidebands_detected", fam.sidebands_detected},
                          {"modulation_lines", fam.modulation_lines},
                          {"explained", fam.explained},
                          {"score_db", fam.score_db},
                          {"passes", fam.passes}});
          // -- end bearing evidence --
        }
        return fams;
      };
      bearings.push_back({{"bearing", b.bearing},
                          {"shaft", b.shaft},
                          {"frequencies",
                           {{"shaft_hz", f.shaft_hz},
                            {"ftf_hz", f.ftf_hz},
                            {"bpfo_hz", f.bpfo_hz},
                            {"bpfi_hz", f.bpfi_hz},
                            {"bsf_hz", f.bsf_hz},
                            {"ball_fault_hz", f.ball_fault_hz}}},
                          {"bands", bands},
                          {"decision",
                           {{"diagnosed", b.diagnosed},
                            {"status", to_string(b.diagnosis.status)},
                            {"fault", to_string(b.diagnosis.fault)},
                            {"note", b.diagnosis.note},  // h/bearings: "cage" note or ""
                            {"band_centre_hz", b.band_centre_hz},
                            {"band_width_hz", b.band_width_hz},
                            {"families", families(b.diagnosis.band_decision)},
                            {"whole_band_families", families(b.diagnosis.whole_decision)}}}});
    }
    cj["bearings"] = bearings;
    cj["notes"] = c.notes;
    j["channels"].push_back(std::move(cj));
  }
  j["two_direction"] = json::array();
  for (const auto& t : r.two_direction) {
    json h = json::array();
    for (const auto& e : t.comparison.harmonics) {
      h.push_back({{"harmonic", e.harmonic},
                   {"frequency_hz", e.frequency_hz},
                   {"along", e.along},
                   {"normal", e.normal},
                   {"valid", e.valid}});
    }
    j["two_direction"].push_back({{"location", t.location},
                                  {"along_channel", t.along_channel},
                                  {"normal_channel", t.normal_channel},
                                  {"mesh", t.mesh},
                                  {"mesh_hz", t.comparison.mesh_hz},
                                  {"along_energy", t.comparison.along_energy},
                                  {"normal_energy", t.comparison.normal_energy},
                                  {"normal_to_along_db", t.comparison.normal_to_along_db},
                                  {"harmonics", h}});
  }
  if (r.gear_damage) {
    j["gear_damage"] = to_json(*r.gear_damage);
    j["gear_damage"]["angles"] = r.gear_damage_angles;
  }
  j["findings"] = json::array();
  for (const auto& f : r.findings) {
    json fj{{"kind", f.kind}, {"confidence", f.confidence}, {"note", f.note}};
    if (!f.shaft.empty()) fj["shaft"] = f.shaft;
    if (!f.gears.empty()) fj["gears"] = f.gears;
    if (!f.bearing.empty()) fj["bearing"] = f.bearing;
    if (!f.fault.empty()) fj["fault"] = f.fault;
    if (std::isfinite(f.frequency_hz)) fj["frequency_hz"] = f.frequency_hz;
    if (!f.channel.empty()) fj["channel"] = f.channel;
    j["findings"].push_back(std::move(fj));
  }
  if (r.baseline) {
    j["anomaly_score"] = r.baseline->anomaly_score;
    j["alarm"] = r.baseline->alarm;
    j["anomaly_threshold"] = r.baseline->threshold;
    j["baseline_deviations"] = json::array();
    for (const auto& d : r.baseline->deviations) {
      j["baseline_deviations"].push_back({{"feature", d.feature},
                                          {"value", d.value},
                                          {"baseline_centre", d.baseline_centre},
                                          {"baseline_spread", d.baseline_spread},
                                          {"z", d.z}});
    }
    j["baseline"] = {{"recordings", r.baseline->recordings},
                     {"samples", r.baseline->samples},
                     {"channels", r.baseline->channels},
                     {"notes", r.baseline->notes}};
  }
  j["notes"] = r.notes;
  return j;
}

std::string format_summary(const AnalysisResult& r) {
  std::ostringstream o;
  o << "recording: " << r.channels.size() << " channels, " << fmt(r.duration_s, 6) << " s";
  if (!r.gearbox_name.empty()) o << ", gearbox " << r.gearbox_name;
  o << "\n";
  if (!r.speed.source.empty()) {
    o << "  speed of " << r.speed.reference_shaft << " from the " << r.speed.source
      << (r.speed.line.empty() ? "" : " (" + r.speed.line + ")") << ": " << fmt(r.speed.mean_rpm, 6)
      << " rpm";
    if (!r.speed.stationary) {
      o << ", varying " << fmt(r.speed.min_rpm, 5) << " .. " << fmt(r.speed.max_rpm, 5) << " rpm";
    }
    o << " (nominal " << fmt(r.speed.nominal_rpm, 6) << " rpm)\n";
  }
  for (const auto& s : r.shafts) {
    o << "  shaft " << s.shaft << ": " << fmt(s.speed_hz * 60, 6) << " rpm (" << s.source << ")\n";
  }
  for (const auto& m : r.meshes) {
    o << "  mesh " << m.name << ": " << fmt(m.frequency_hz, 6) << " Hz\n";
  }
  o << "channels:\n";
  for (const auto& c : r.channels) {
    o << "  " << c.name << " [" << (c.unit.empty() ? "-" : c.unit) << "] rms " << fmt(c.time.rms)
      << " peak " << fmt(c.time.peak) << " crest " << fmt(c.time.crest_factor) << " kurtosis "
      << fmt(c.time.kurtosis);
    if (c.vibration && !c.spectrum_peaks.empty()) {
      o << "; top line " << fmt(c.spectrum_peaks.front().frequency_hz, 6) << " Hz";
    }
    o << "\n";
  }
  if (!r.two_direction.empty()) {
    o << "two directions (normal / along at the mesh harmonics):\n";
    for (const auto& t : r.two_direction) {
      o << "  " << t.location << " mesh " << t.mesh << ": " << fmt(t.comparison.normal_to_along_db)
        << " dB\n";
    }
  }
  if (r.gear_damage) {
    o << "damaged-shaft location (TSA per shaft, angles from the " << r.gear_damage_angles
      << "): " << r.gear_damage->status << "\n";
    for (const auto& s : r.gear_damage->shafts) {
      o << "  " << s.shaft << ": ";
      if (s.revolutions == 0) {
        o << "skipped\n";
        continue;
      }
      o << "score " << fmt(s.score) << ", SNR " << fmt(s.snr) << ", level " << fmt(s.level)
        << " on " << s.channel << " (" << s.revolutions << " revolutions)"
        << (s.damaged     ? ": DAMAGED"
            : s.uncertain ? ": uncertain"
                          : "")
        << "\n";
    }
  }
  o << "findings:";
  if (r.findings.empty()) o << " none";
  o << "\n";
  for (const auto& f : r.findings) {
    o << "  [" << fmt(f.confidence, 2) << "] " << f.kind << ": "
      << (f.bearing.empty() ? f.shaft : f.bearing + " " + f.fault) << " - " << f.note << "\n";
  }
  if (r.baseline) {
    o << "anomaly score " << fmt(r.baseline->anomaly_score) << " (threshold "
      << fmt(r.baseline->threshold) << "): " << (r.baseline->alarm ? "ALARM" : "normal") << "\n";
    const auto& ch = r.baseline->channels;
    o << "  against " << r.baseline->recordings.size() << " baseline recordings ("
      << r.baseline->samples << " samples), "
      << (ch.size() <= 6 ? "channels " + joined(ch) : std::to_string(ch.size()) + " channels")
      << "\n";
    for (std::size_t k = 0; k < std::min<std::size_t>(3, r.baseline->deviations.size()); ++k) {
      const auto& d = r.baseline->deviations[k];
      o << "  " << d.feature << ": z " << fmt(d.z) << " (" << fmt(d.value) << " against "
        << fmt(d.baseline_centre) << " +- " << fmt(d.baseline_spread) << ")\n";
    }
    for (const auto& n : r.baseline->notes) o << "  note: " << n << "\n";
  }
  for (const auto& n : r.notes) o << "note: " << n << "\n";
  return o.str();
}

}  // namespace detect
