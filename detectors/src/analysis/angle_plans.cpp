// analyze's angle-plans stage (stages.hpp).
#include <algorithm>
#include <atomic>
#include <exception>
#include <functional>
#include <span>
#include <thread>

#include "detect/angular/tsa.hpp"
#include "diag/error.hpp"
#include "stages.hpp"

namespace detect::analysis_stages {

int tsa_samples_per_rev(const diag::Gearbox& gb, std::size_t s, const AnalyzeOptions& opt) {
  int zmax = 1;
  for (int g : gb.shafts()[s].gears)
    zmax = std::max(zmax, gb.gears()[static_cast<std::size_t>(g)].spec.teeth);
  const double top = opt.gear_metrics.mesh_harmonics * zmax + opt.gear_metrics.ser_sidebands;
  return static_cast<int>(
      std::clamp<std::size_t>(pow2_at_least(kOrderOversampling * top), 64, kMaxSamplesPerRev));
}

// The order plan's kept taps at most [values of 8 bytes]: 32 MiB (the two-stage run-up 500 ->
// 3000 rpm, 10 s at 20 kHz: 3.9 M).
constexpr std::size_t kKeptTaps = std::size_t{1} << 22;

AngularRecords angle_plans_stage(const AnalysisContext& ctx) {
  const diag::Recording& rec = ctx.rec;
  const diag::Gearbox* gb = ctx.gb;
  const AnalyzeOptions& opt = ctx.opt;
  const ShaftKinematics& kin = ctx.kin;
  AngularRecords a;
  if (!gb) return a;
  // One angle plan per shaft for every channel of the common rate and length (resample.hpp: its
  // taps are computed once; applied per channel it gives the same bytes as the one-call form). A
  // channel of another rate or length, or a plan that cannot be built (too few revolutions: the
  // one-call form then says why in the channel's notes), resamples on its own.
  for (const diag::Signal& sig : rec.signals) {
    if (sig.role == diag::Role::kVibration) {
      a.plan_fs = sig.fs_hz;
      a.plan_n = sig.samples.size();
      break;
    }
  }
  // The order spectrum's angular sampling: 2.8 x the highest order of interest; in the order
  // domain at least the record's own samples per revolution at the mean speed, so that the
  // resampled record keeps the band the recording has (fs / 2 at the mean speed).
  double orders = kOrderOversampling * ctx.max_input_order;
  if (ctx.order_domain && a.plan_fs > 0) orders = std::max(orders, a.plan_fs / ctx.input_hz);
  a.order_ro.samples_per_rev =
      static_cast<int>(std::clamp<std::size_t>(pow2_at_least(orders), 64, kMaxSamplesPerRev));
  // In the order domain a tacho's pulse times are smoothed first (kinematics.hpp): each pulse of
  // an ideal edge is uncertain by up to half a sampling period (tacho.hpp), i.e. 2.5e-3 rev at
  // 3000 rpm and 10 kHz, a phase noise of 0.85 rad on the 54th order, which the cubic angle
  // between pulses spreads into skirts around every mesh line that the sideband vote takes for
  // shaft-rate sidebands. Measured on the healthy two-stage run-up 500 -> 3000 rpm
  // (analyze_run_up_test.cpp): raw pulses: mesh z1_z2 "pointed" at the input in 21 of 28
  // channels; +-4 revolutions: at the counter in 15 of 28; +-10 and +-20: no channel count
  // passes. The TSA and the locator use the pulses corrected once (refine_tsa_pulses,
  // kinematics.hpp): a polynomial fit over the record and a mesh line's phase.
  // The speed from the vibration has no such jitter (its angle is the mesh line's phase).
  constexpr int kTachoSmoothingHalfWindow = 10;
  const auto& input_pulses = kin.pulses_s[static_cast<std::size_t>(ctx.input)];
  a.order_pulses = ctx.order_domain && kin.speed.source == "tacho"
                       ? smooth_pulse_times_local_quadratic(input_pulses, kTachoSmoothingHalfWindow)
                       : input_pulses;
  std::vector<std::optional<AnglePlan>> tsa_plans(gb->shafts().size());
  // The plans may read the records decimated first (resample.hpp: half-band stages, shared by
  // every plan of the same stages, each output equal to the direct one to 1e-5 of the band kept
  // plus the kernels' -80 dB stopband): each plan's kernel then spans 2^s times fewer samples.
  // Not the order plan in the order domain: it keeps the recording's whole band there, and the
  // envelope stage applies it again to the full-rate envelopes.
  constexpr int kDecimation = 3;
  if (a.plan_n > 0) {
    try {
      ResampleOptions ro = a.order_ro;
      if (!ctx.order_domain) ro.decimation = kDecimation;
      a.order_plan.emplace(make_angle_plan(a.order_pulses, a.plan_fs, a.plan_n, ro));
    } catch (const diag::InputError&) {
    }
    for (std::size_t s = 0; s < tsa_plans.size(); ++s) {
      const auto& pulses = kin.tsa_pulses_s[s];
      const int revs = pulses.size() > 1 ? static_cast<int>(pulses.size()) - 1 : 0;
      if (gb->shafts()[s].gears.empty() || revs < opt.tsa_min_revolutions) continue;
      try {
        TsaOptions to;
        to.samples_per_rev = tsa_samples_per_rev(*gb, s, opt);
        to.min_revolutions = opt.tsa_min_revolutions;
        ResampleOptions ro = to.resample_options();
        ro.decimation = kDecimation;
        tsa_plans[s].emplace(make_angle_plan(pulses, a.plan_fs, a.plan_n, ro));
      } catch (const diag::InputError&) {
      }
    }
  }

  // Every sharing channel through each plan in one call (the kernel taps of an output sample are
  // computed once for all channels: the cost of resampling); the plans in parallel.
  const std::size_t nsig = rec.signals.size();
  std::vector<std::size_t> which;
  for (std::size_t i = 0; i < nsig; ++i) {
    const diag::Signal& sig = rec.signals[i];
    const bool spectra = sig.role == diag::Role::kVibration || sig.role == diag::Role::kForce ||
                         sig.role == diag::Role::kDisplacement;
    if (spectra && a.shares_plans(sig) && sig.samples.size() >= 64) which.push_back(i);
  }
  // decimated[s - 1][k]: channel which[k] decimated s times, for the stages some plan takes.
  int stages = 0;
  if (a.order_plan) stages = a.order_plan->decimation();
  for (const auto& p : tsa_plans) {
    if (p) stages = std::max(stages, p->decimation());
  }
  std::vector<std::vector<std::vector<double>>> decimated(static_cast<std::size_t>(stages));
  for (auto& d : decimated) d.resize(which.size());
  diag::parallel_for(which.size(), opt.threads, [&](std::size_t k) {
    std::span<const double> x = rec.signals[which[k]].samples;
    for (std::size_t s = 0; s < decimated.size(); ++s) {
      decimated[s][k] = decimate_half_band(x, 1);
      x = decimated[s][k];
    }
  });
  auto through = [&](const AnglePlan& plan) {
    std::vector<std::span<const double>> xs;
    for (std::size_t k = 0; k < which.size(); ++k) {
      xs.push_back(plan.decimation() == 0
                       ? std::span<const double>(rec.signals[which[k]].samples)
                       : std::span<const double>(
                             decimated[static_cast<std::size_t>(plan.decimation()) - 1][k]));
    }
    std::vector<std::optional<AngleResampled>> out(nsig);
    std::vector<AngleResampled> ar = resample_by_angle(xs, plan);
    for (std::size_t k = 0; k < which.size(); ++k) out[which[k]] = std::move(ar[k]);
    return out;
  };
  // In the order domain the envelope stage applies the order plan again, one channel at a time
  // (channel_envelope.cpp): the plan keeps its taps from the first application (resample.hpp)
  // when they fit in kKeptTaps values.
  if (a.order_plan && ctx.order_domain) a.order_plan->keep_taps(kKeptTaps);
  a.tsa_resampled.resize(tsa_plans.size());
  std::vector<std::function<void()>> jobs;
  // At steady speed the order plan's records feed the order spectrum only, which is drawn only
  // (AnalyzeOptions::traces): without a plot they are not made (spectral_record,
  // channel_spectra.cpp).
  if (a.order_plan && (ctx.order_domain || opt.traces))
    jobs.emplace_back([&] { a.order_resampled = through(*a.order_plan); });
  for (std::size_t s = 0; s < tsa_plans.size(); ++s) {
    if (tsa_plans[s]) jobs.emplace_back([&, s] { a.tsa_resampled[s] = through(*tsa_plans[s]); });
  }
  diag::parallel_for(jobs.size(), opt.threads, [&](std::size_t k) { jobs[k](); });
  return a;
}

}  // namespace detect::analysis_stages
