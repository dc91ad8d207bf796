// analyze's comparison with healthy baseline recordings (score_against_baseline, analyze.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "detect/baseline/baseline.hpp"
#include "detect/baseline/mesh_harmonic_growth.hpp"
#include "diag/error.hpp"
#include "kinematics.hpp"
#include "stages.hpp"

namespace detect {

using analysis_stages::fmt;

void BaselineComparisonOptions::validate() const {
  features.validate();
  baseline.validate();
  if (segments_per_recording < 1 || segments_per_recording > 64)
    throw diag::InputError("score_against_baseline: segments_per_recording: " +
                           std::to_string(segments_per_recording) + " is not in [1, 64]");
  for (const auto& [mesh, db] : wear_threshold_db) {
    if (!std::isfinite(db) || db <= 0)
      throw diag::InputError("score_against_baseline: wear_threshold_db: mesh " + mesh + ": " +
                             fmt(db, 6) + " is not a finite threshold > 0 dB");
  }
}

namespace {

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
                             diag::format_list(theirs) +
                             "; the recording's: " + diag::format_list(sensor_names) + ")");
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
                           diag::format_list(out.notes) + ")");
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

void wear_against_baseline(AnalysisResult& r, const diag::Recording& rec, const diag::Gearbox& gb,
                           std::span<const diag::Recording> baseline, const AnalyzeOptions& opt,
                           std::span<const std::string> names,
                           const std::map<std::string, double>& wear_threshold_db) {
  if (!r.baseline) throw std::logic_error("wear_against_baseline: no baseline comparison in r");
  if (!names.empty() && names.size() != baseline.size())
    throw diag::InputError("wear_against_baseline: names: " + std::to_string(names.size()) +
                           " names for " + std::to_string(baseline.size()) +
                           " baseline recordings");
  AnalysisBaseline& out = *r.baseline;
  if (baseline.empty() || r.meshes.size() != gb.meshes().size()) return;
  auto name_of = [&](std::size_t i) {
    return names.empty() ? "baseline recording " + std::to_string(i + 1) : names[i];
  };
  const std::string what = "wear indicator (mesh-harmonic growth): ";
  if (!r.speed.stationary) {
    out.notes.push_back(what + "not read: the recording's speed varies (it compares time spectra)");
    return;
  }
  // Each baseline recording's input speed, estimated as the analysis estimates the recording's.
  const int input = gb.input_shaft();
  std::vector<double> scale(baseline.size());  // baseline input speed / gb's nominal
  for (std::size_t i = 0; i < baseline.size(); ++i) {
    const diag::Recording& b = baseline[i];
    const diag::Gearbox gb_b = b.speed_rpm > 0 ? gb.with_input_speed_rpm(b.speed_rpm) : gb;
    double duration = 0;
    for (const diag::Signal& s : b.signals) duration = std::max(duration, s.duration_s());
    std::vector<std::string> ignored;  // the baseline's own speed notes: not the report's
    const ShaftKinematics kin = shaft_kinematics(b, gb_b, duration, opt, ignored);
    if (!kin.speed.stationary) {
      out.notes.push_back(what + "not read: the speed of " + name_of(i) +
                          " varies (it compares time spectra)");
      return;
    }
    scale[i] = kin.speeds[static_cast<std::size_t>(input)].speed_hz / gb.shaft_speed_hz(input);
  }
  for (std::size_t j = 0; j < r.meshes.size(); ++j) {
    const AnalysisMesh& m = r.meshes[j];
    MeshHarmonicGrowthOptions mo;
    if (const auto it = wear_threshold_db.find(m.name); it != wear_threshold_db.end()) {
      mo.threshold_db = it->second;
    }
    AnalysisMeshWear w;
    w.mesh = m.name;
    w.mesh_hz = m.frequency_hz;
    for (double s : scale)
      w.baseline_mesh_hz.push_back(gb.mesh_frequency_hz(static_cast<int>(j)) * s);
    try {
      const MeshHarmonicGrowth g =
          mesh_harmonic_growth(rec, w.mesh_hz, baseline, w.baseline_mesh_hz, mo);
      w.growth_db = g.growth_db;
      w.threshold_db = g.threshold_db;
      w.flagged = g.flagged;
      w.channels = g.channels;
      w.channel_db = g.channel_db;
    } catch (const diag::InputError& e) {
      out.notes.push_back(what + "mesh " + m.name + " not read: " + e.what());
      continue;
    }
    if (w.flagged) {
      Finding f;
      f.kind = "wear";
      f.fault = diag::FaultKind::kWear;
      f.shaft =
          gb.shafts()[static_cast<std::size_t>(gb.shaft_of_gear(gb.gear_index(m.driver)))].name;
      f.gears = {m.driver, m.driven};
      const auto best = std::max_element(w.channel_db.begin(), w.channel_db.end());
      f.channel = w.channels[static_cast<std::size_t>(best - w.channel_db.begin())];
      f.frequency_hz = w.mesh_hz;
      f.confidence = std::min(1.0, w.growth_db / (2 * w.threshold_db));
      f.set_evidence("growth_db", w.growth_db);
      f.set_evidence("threshold_db", w.threshold_db);
      f.set_evidence("mesh_frequency_hz", w.mesh_hz);
      f.note = "mesh " + m.name + ": its harmonics " + fmt(w.growth_db, 3) +
               " dB above the baseline's (threshold " + fmt(w.threshold_db, 3) + " dB, mean over " +
               std::to_string(w.channels.size()) + " channels): worn flanks";
      r.findings.push_back(std::move(f));
    }
    out.wear.push_back(std::move(w));
  }
  std::stable_sort(r.findings.begin(), r.findings.end(),
                   [](const Finding& a, const Finding& b) { return a.confidence > b.confidence; });
}

void set_baseline(AnalysisResult& r, AnalysisBaseline b, const BaselineComparisonOptions& opt) {
  r.baseline = std::move(b);
  if (!r.baseline->alarm) return;
  std::map<std::string, double> fs_hz;
  for (const ChannelAnalysis& c : r.channels) fs_hz[c.name] = c.fs_hz;
  r.findings.push_back(baseline_alarm_finding(*r.baseline, fs_hz, opt));
  std::stable_sort(r.findings.begin(), r.findings.end(),
                   [](const Finding& x, const Finding& y) { return x.confidence > y.confidence; });
}

Finding baseline_alarm_finding(const AnalysisBaseline& b,
                               const std::map<std::string, double>& fs_hz,
                               const BaselineComparisonOptions& opt) {
  Finding f;
  f.kind = "baseline";
  f.fault = diag::FaultKind::kAnomaly;
  f.confidence = b.threshold > 0 ? std::min(1.0, b.anomaly_score / (2 * b.threshold)) : 1.0;
  f.evidence = {{"anomaly_score", b.anomaly_score}, {"threshold", b.threshold}};
  std::string what = "the recording departs from its baseline";
  if (!b.deviations.empty()) {
    const AnalysisBaselineDeviation& d = b.deviations.front();  // the largest |z|
    const std::size_t dot = d.feature.rfind('.');
    const std::string channel = dot == std::string::npos ? "" : d.feature.substr(0, dot);
    const std::string feature = d.feature.substr(dot == std::string::npos ? 0 : dot + 1);
    f.channel = channel;
    f.set_evidence("z", d.z);
    const char* moved = d.z > 0 ? " rose" : " fell";
    std::string physical = feature;
    if (feature == "kurtosis_log") physical = "the kurtosis";
    if (feature == "crest_log") physical = "the crest factor";
    if (feature == "skewness") physical = "the skewness";
    if (feature == "flatness_log") physical = "the spectral flatness";
    int band = -1;
    if (std::sscanf(feature.c_str(), "band%d_log_fraction", &band) == 1 && fs_hz.count(channel)) {
      // The band's edges (baseline.hpp): f_lo (fs / (2 f_lo))^(i / bands).
      const double fs = fs_hz.at(channel);
      const double lo = opt.features.lowest_band_fraction * fs;
      const double r = std::pow(0.5 * fs / lo, 1.0 / opt.features.bands);
      const double a = lo * std::pow(r, band), c = lo * std::pow(r, band + 1);
      f.set_evidence("band_low_hz", a);
      f.set_evidence("band_high_hz", c);
      f.frequency_hz = std::sqrt(a * c);
      physical = "the share of the PSD in " + analysis_stages::fmt(a, 3) + "-" +
                 analysis_stages::fmt(c, 3) + " Hz";
    }
    what = physical + moved + " on " + channel + " (z = " + analysis_stages::fmt(d.z, 3) +
           " robust sigmas over the baseline)";
  }
  f.note = "anomaly score " + analysis_stages::fmt(b.anomaly_score, 3) +
           " against the baseline, above the threshold " + analysis_stages::fmt(b.threshold, 3) +
           ": " + what;
  return f;
}

}  // namespace detect
