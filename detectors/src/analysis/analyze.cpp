// analyze_recording: the recording-level stages run in order from their table (kinematics,
// angle plans, the channels, the whole record, two directions, the locator, findings), the
// channels each through the table of channel stages (stages.hpp), in parallel; and the options'
// checks and the plot decimation the stages share.
#include "detect/analysis/analyze.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <span>
#include <string_view>
#include <utility>

#include "diag/error.hpp"
#include "diag/io/channels.hpp"
#include "diag/util/parallel_for.hpp"
#include "kinematics.hpp"
#include "stages.hpp"

namespace detect {

namespace {

using namespace analysis_stages;

void require(bool ok, const std::string& field, const std::string& reason) {
  if (!ok) throw diag::InputError("analyze: " + field + ": " + reason);
}

// CPU time of the calling thread [s]: a channel's stages run on one worker thread, so this is
// the stage's own CPU whatever the thread count.
double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The needs of `needs` a channel lacks (ChannelNeed bits; 0: every one met).
unsigned channel_needs_unmet(const ChannelWork& w, unsigned needs) {
  unsigned unmet = 0;
  for (unsigned bit = 1; bit <= kTraces; bit <<= 1) {
    if ((needs & bit) == 0 || channel_needs_met(w, bit)) continue;
    // No spectral record because the channel is no vibration channel: that is the reason.
    unmet |= bit == kSpectralRecord && !w.out.vibration ? kVibrationChannel : bit;
  }
  return unmet;
}

// One channel through the rows of kChannelStages whose needs it meets. Channels are independent,
// so they run in parallel (FFT plans are shared and thread-safe, fft.hpp) and each writes only
// its own slots: same bytes whatever the thread count. `spectrum` gets the channel's whole
// amplitude spectrum (the two-direction stage reads it); `cpu` (empty unless timed) gets each
// stage's CPU time, one slot per row of the table; `unmet`, per row, the needs this channel
// lacked (0: the stage ran).
ChannelAnalysis analyse_channel(const AnalysisContext& ctx, const AngularRecords& ang,
                                std::size_t ci, Spectrum& spectrum, std::span<double> cpu,
                                std::span<unsigned> unmet) {
  ChannelAnalysis c;
  ChannelWork w{ctx, ang, ci, ctx.rec.signals[ci], c, {}, {}, {}};
  for (std::size_t k = 0; k < std::size(kChannelStages); ++k) {
    const ChannelStage& stage = kChannelStages[k];
    unmet[k] = channel_needs_unmet(w, stage.needs);
    if (unmet[k] != 0) continue;
    const double t0 = cpu.empty() ? 0.0 : thread_cpu_s();
    stage.run(w);
    if (!cpu.empty()) cpu[k] += thread_cpu_s() - t0;
  }
  spectrum = std::move(w.spectrum);
  return c;
}

// The first index of the largest (largest) or smallest value of y[i0, i1), i0 < i1, as a scan
// in index order that replaces its pick only by a strictly larger (smaller) value: NaNs are
// skipped, and a NaN at i0 is kept. Two passes, for speed: the extreme over four independent
// lanes (no loop-carried compare-and-select chain), then the first index holding it.
std::size_t first_extreme(std::span<const double> y, std::size_t i0, std::size_t i1, bool largest) {
  if (std::isnan(y[i0])) return i0;
  const double s = largest ? 1.0 : -1.0;  // compare s y: the largest of s y
  double m[4] = {s * y[i0], s * y[i0], s * y[i0], s * y[i0]};
  std::size_t i = i0 + 1;
  for (; i + 4 <= i1; i += 4) {
    for (std::size_t q = 0; q < 4; ++q) {
      const double v = s * y[i + q];
      m[q] = v > m[q] ? v : m[q];
    }
  }
  for (; i < i1; ++i) m[0] = s * y[i] > m[0] ? s * y[i] : m[0];
  const double top = std::max(std::max(m[0], m[1]), std::max(m[2], m[3]));
  i = i0;
  while (s * y[i] != top) ++i;
  return i;
}

// Cuts a channel's amplitude spectrum above the bins the two-direction stage reads: the band
// h f_mesh +- w of every harmonic h <= H of every mesh, w = halfwidth_hz, or (0) max(4 bins, 1 %
// of h f_mesh) (two_direction.hpp), so up to H f + max(4 bins, 0.01 H f) for the fastest mesh;
// 4 bins more are kept against round-off. Every band inside the spectrum stays inside it with
// the same bins, and one that runs past its end still does.
void keep_two_direction_bins(const TwoDirectionOptions& o, const std::vector<AnalysisMesh>& meshes,
                             Spectrum& sp) {
  double top = 0;
  for (const AnalysisMesh& m : meshes) top = std::max(top, m.frequency_hz);
  const double res = sp.resolution_hz;
  if (!(top > 0) || !(res > 0) || sp.frequency_hz.empty()) return;
  const double f = o.mesh_harmonics * top;
  const double w = o.halfwidth_hz > 0 ? o.halfwidth_hz : std::max(4 * res, 0.01 * f);
  const double last = std::ceil((f + w) / res) + 8;  // 4 bins of round-off in w, 4 more
  if (!(last + 1 < static_cast<double>(sp.frequency_hz.size()))) return;
  const auto keep = static_cast<std::size_t>(last) + 1;
  sp.frequency_hz.resize(keep);
  sp.amplitude.resize(keep);
  sp.frequency_hz.shrink_to_fit();
  sp.amplitude.shrink_to_fit();
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
  require(std::isfinite(nominal_time_s), "nominal_time_s", "must be finite");
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
    const std::size_t hi = first_extreme(y, i0, i1, true);
    if (max_only) {
      t.x.push_back(x[hi]);
      t.y.push_back(y[hi]);
      continue;
    }
    const std::size_t lo = first_extreme(y, i0, i1, false);
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

namespace {

// What the recording-level stages share: the result being filled, the kinematics and the
// context every later stage reads, the angle plans, and each channel's whole amplitude spectrum
// (kept for the two-direction stage).
struct RecordWork {
  RecordWork(const diag::Recording& rec, const diag::Gearbox* gb, const AnalyzeOptions& opt,
             AnalysisResult& result)
      : r(result), ctx{rec, gb, opt, kin, result.meshes, -1, 0.0, 0.0, false, 0, {}, {}} {}
  AnalysisResult& r;
  ShaftKinematics kin;
  AnalysisContext ctx;
  AngularRecords ang;
  std::vector<Spectrum> spectra;
};

enum RecordNeed : unsigned {
  kWithGearbox = 1u << 0,  // a gearbox description
};

// The shaft speeds and angles, the speed report, the meshes at the measured speed and what the
// later stages derive from them (kinematics.hpp).
void kinematics_stage(RecordWork& w) {
  AnalysisContext& ctx = w.ctx;
  AnalysisResult& r = w.r;
  const diag::Gearbox& gb = *ctx.gb;
  const AnalyzeOptions& opt = ctx.opt;
  ShaftKinematics& kin = w.kin;
  r.gearbox_name = gb.name();
  kin = shaft_kinematics(ctx.rec, gb, r.duration_s, opt, r.notes);
  refine_tsa_pulses(ctx.rec, gb, opt, kin, r.notes);
  r.shafts = kin.speeds;
  r.speed = kin.speed;
  // At varying speed every spectrum of a channel is an order spectrum: the channel resampled
  // at uniform angles of the input shaft and read as a record at the constant mean speed (its
  // "sampling rate" samples_per_rev x mean input speed), so that a line of order q sits at
  // q x the mean speed whatever the speed did (computed order tracking; Fyfe & Munck 1997,
  // MSSP 11(2)). The envelope is demodulated in time first (a structural resonance is fixed
  // in Hz, not in orders), then resampled (the envelope order spectrum; Borghesani, Ricci,
  // Chatterton, Pennacchi 2013, MSSP 38(1)).
  ctx.order_domain = !kin.speed.stationary;
  r.speed.spectra_domain = ctx.order_domain ? "order" : "time";
  if (ctx.order_domain) {
    r.notes.push_back(
        "the speed varies over the record (" + fmt(kin.speed.min_rpm, 5) + " to " +
        fmt(kin.speed.max_rpm, 5) +
        " rpm): spectra, sidebands and envelope spectra are computed in the order domain (the "
        "signal resampled at uniform angles of the input shaft) and their frequencies stated at "
        "the mean speed (order x mean shaft speed); the TSA and the damaged-shaft locator "
        "follow the shaft angles");
  }
  ctx.input = gb.input_shaft();
  r.input_shaft = gb.shafts()[static_cast<std::size_t>(ctx.input)].name;
  ctx.input_hz = kin.speeds[static_cast<std::size_t>(ctx.input)].speed_hz;
  const double scale = ctx.input_hz / gb.shaft_speed_hz(ctx.input);
  for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
    const diag::Mesh& m = gb.meshes()[j];
    r.meshes.push_back({diag::mesh_name(gb, static_cast<int>(j)), gb.gears()[m.driver].name,
                        gb.gears()[m.driven].name,
                        gb.mesh_frequency_hz(static_cast<int>(j)) * scale});
  }
  // Highest order of interest in input-shaft orders: H mesh harmonics plus K sidebands.
  double max_mesh = 0, max_shaft = 0;
  for (const auto& m : r.meshes) max_mesh = std::max(max_mesh, m.frequency_hz);
  for (const auto& s : r.shafts) max_shaft = std::max(max_shaft, s.speed_hz);
  ctx.max_input_order =
      (opt.sidebands.mesh_harmonics * max_mesh + opt.sidebands.sidebands * max_shaft) /
      ctx.input_hz;
}

// Every channel through the channel stages, in parallel; with timing, the CPU time of each
// channel stage summed over the channels ("channel_cpu.<stage>"; the stage's own wall time is
// shared by the threads).
void channels_stage(RecordWork& w) {
  const AnalysisContext& ctx = w.ctx;
  AnalysisResult& r = w.r;
  const AnalyzeOptions& opt = ctx.opt;
  const std::size_t nc = ctx.rec.signals.size();
  constexpr std::size_t kStages = std::size(kChannelStages);
  w.spectra.assign(nc, Spectrum{});
  r.channels.resize(nc);
  std::vector<double> cpu(opt.timing ? nc * kStages : 0, 0.0);
  std::vector<unsigned> unmet(nc * kStages, 0u);
  diag::parallel_for(nc, opt.threads, [&](std::size_t ci) {
    const std::span<double> own =
        opt.timing ? std::span<double>(cpu).subspan(ci * kStages, kStages) : std::span<double>();
    r.channels[ci] = analyse_channel(ctx, w.ang, ci, w.spectra[ci], own,
                                     std::span<unsigned>(unmet).subspan(ci * kStages, kStages));
    // Only the two-direction stage reads a channel's spectrum afterwards, and only an along- or
    // normal-LOA channel's, up to its highest band: any other is freed now, and an LOA channel's
    // is cut above that band (two record-length vectors per channel otherwise).
    const diag::Direction d = r.channels[ci].direction;
    if (!ctx.gb || (d != diag::Direction::kAlongLoa && d != diag::Direction::kNormalLoa)) {
      w.spectra[ci] = Spectrum{};
    } else {
      keep_two_direction_bins(opt.two_direction, r.meshes, w.spectra[ci]);
    }
  });
  // What ran on how many channels, and why not on the others (in the order of the needs; the
  // plot-only stages are not listed).
  static constexpr std::pair<unsigned, const char*> kWhy[] = {
      {kVibrationChannel, "not a vibration, force or displacement channel"},
      {kSpectralRecord,
       "no record to take spectra of (under 64 samples, or its angle-domain "
       "resampling failed: the channel's notes say which)"},
      {kSensorChannel, "not a sensor (does not vote)"},
      {kGearbox, "no gearbox description"},
  };
  for (std::size_t k = 0; k < kStages; ++k) {
    // A plot-only stage is left out: the report is the same whether plots are asked for or not.
    if ((kChannelStages[k].needs & kTraces) != 0) continue;
    StageRun run{std::string("channel.") + kChannelStages[k].name, 0, 0, {}};
    unsigned lacking = 0;
    for (std::size_t ci = 0; ci < nc; ++ci) {
      const unsigned u = unmet[ci * kStages + k];
      ++(u == 0 ? run.ran : run.skipped);
      lacking |= u;
    }
    for (const auto& [bit, why] : kWhy) {
      if ((lacking & bit) != 0) run.why += (run.why.empty() ? "" : "; ") + std::string(why);
    }
    r.stages.push_back(std::move(run));
  }
  for (std::size_t k = 0; k < kStages && opt.timing; ++k) {
    double total = 0;
    for (std::size_t ci = 0; ci < nc; ++ci) total += cpu[ci * kStages + k];
    r.timing_s[std::string("channel_cpu.") + kChannelStages[k].name] = total;
  }
}

// The recording-level stages, in order; a stage whose needs are not met is skipped. The name
// is what AnalyzeOptions::progress is called with as the stage starts and the key of its wall
// time in AnalysisResult::timing_s.
struct RecordStage {
  const char* name;
  unsigned needs;  // RecordNeed bits
  void (*run)(RecordWork&);
};
constexpr RecordStage kRecordStages[] = {
    {"kinematics", kWithGearbox, kinematics_stage},
    {"angle_plans", 0, [](RecordWork& w) { w.ang = angle_plans_stage(w.ctx); }},
    {"channels", 0, channels_stage},
    {"two_direction", kWithGearbox,
     [](RecordWork& w) { two_direction_stage(w.ctx, w.spectra, w.r); }},
    {"gear_damage", kWithGearbox, [](RecordWork& w) { gear_damage_stage(w.ctx, w.r); }},
    {"findings", kWithGearbox, [](RecordWork& w) { fuse_findings(w.ctx, w.r); }},
};

}  // namespace

bool analysis_stages::channel_needs_met(const ChannelWork& w, unsigned needs) {
  const auto need = [needs](ChannelNeed n) { return (needs & n) != 0; };
  return !(need(kVibrationChannel) && !w.out.vibration) &&
         !(need(kSpectralRecord) && !w.record.spectral()) &&
         !(need(kSensorChannel) && !w.out.sensor) && !(need(kGearbox) && !w.ctx.gb) &&
         !(need(kTraces) && !w.ctx.opt.traces);
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
  RecordWork w(rec, gb, opt, r);
  AnalysisContext& ctx = w.ctx;
  ctx.plot_points = static_cast<std::size_t>(opt.plot_points);
  const std::size_t nc = rec.signals.size();
  ctx.sensor.assign(nc, false);
  for (std::size_t i : sensor_channels(rec)) ctx.sensor[i] = true;
  // A bearing is examined on the sensor channels at it, or on every sensor channel when none is.
  ctx.located.assign(gb ? gb->bearings().size() : 0, false);
  for (std::size_t b = 0; b < ctx.located.size(); ++b)
    for (std::size_t i = 0; i < nc; ++i)
      ctx.located[b] =
          ctx.located[b] || (ctx.sensor[i] && rec.signals[i].location == gb->bearings()[b].name);
  if (!gb) r.notes.push_back("no gearbox description: unit-free indicators and spectra only");

  const unsigned have = gb ? kWithGearbox : 0u;
  for (const RecordStage& stage : kRecordStages) {
    if ((stage.needs & have) != stage.needs) {
      r.stages.push_back({stage.name, 0, 1, "no gearbox description"});
      continue;
    }
    if (std::string_view(stage.name) != "channels") r.stages.push_back({stage.name, 1, 0, {}});
    if (opt.progress) opt.progress(stage.name);
    // Wall time per stage (AnalyzeOptions::timing; left out otherwise, so reports stay
    // byte-equal).
    const auto t0 = std::chrono::steady_clock::now();
    stage.run(w);
    if (opt.timing) {
      r.timing_s[stage.name] +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
  }
  return r;
}

}  // namespace detect
