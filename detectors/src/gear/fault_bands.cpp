#include "detect/gear/fault_bands.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "diag/error.hpp"
#include "diag/range_check.hpp"

namespace detect {

using diag::InputError;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string band_label(const std::string& family, int h, int k) {
  std::string s = std::to_string(h) + "x" + family;
  if (k != 0) s += (k > 0 ? "+" : "-") + std::to_string(std::abs(k)) + "xSB";
  return s;
}

// Index range [first, last) of bins with lo <= f <= hi.
std::pair<std::size_t, std::size_t> bins_between(std::span<const double> f, double lo, double hi) {
  const auto first = std::lower_bound(f.begin(), f.end(), lo);
  const auto last = std::upper_bound(first, f.end(), hi);
  return {static_cast<std::size_t>(first - f.begin()), static_cast<std::size_t>(last - f.begin())};
}

double bin_energy(const SpectrumView& s, std::size_t k, SpectrumScale scale) {
  const double v = s.value[k];
  switch (scale) {
    case SpectrumScale::kAmplitude:
      return v * v;
    case SpectrumScale::kPower:
      return v;
    case SpectrumScale::kPowerDensity: {
      const auto& f = s.frequency_hz;
      const std::size_t n = f.size();
      const double width = k == 0       ? f[1] - f[0]
                           : k == n - 1 ? f[n - 1] - f[n - 2]
                                        : 0.5 * (f[k + 1] - f[k - 1]);
      return v * width;
    }
  }
  return 0;
}

}  // namespace

void SpectrumView::validate(const std::string& where) const {
  if (frequency_hz.size() != value.size())
    throw InputError(diag::format_error(where, "spectrum",
                                        "frequency_hz has " + std::to_string(frequency_hz.size()) +
                                            " bins but value has " + std::to_string(value.size())));
  if (frequency_hz.size() < 3)
    diag::fail_range(where, "spectrum.frequency_hz.size", frequency_hz.size(), ">= 3 bins");
  for (std::size_t k = 0; k < frequency_hz.size(); ++k) {
    if (!std::isfinite(frequency_hz[k]) || (k > 0 && !(frequency_hz[k] > frequency_hz[k - 1])))
      diag::fail_range(where, "spectrum.frequency_hz[" + std::to_string(k) + "]", frequency_hz[k],
                       "finite, strictly increasing");
    if (!(value[k] >= 0) || !std::isfinite(value[k]))
      diag::fail_range(where, "spectrum.value[" + std::to_string(k) + "]", value[k],
                       "finite, >= 0");
  }
}

// ---- Bands --------------------------------------------------------------------------------------

void FaultBandOptions::validate() const {
  if (harmonics < 1 || harmonics > 100)
    diag::fail_range("FaultBandOptions", "harmonics", harmonics, "1..100");
  if (sidebands < 0 || sidebands > 20)
    diag::fail_range("FaultBandOptions", "sidebands", sidebands, "0..20");
  if (!(width_hz >= 0) || !std::isfinite(width_hz))
    diag::fail_range("FaultBandOptions", "width_hz", width_hz, ">= 0");
}

std::vector<FaultBand> fault_bands(std::span<const FaultFrequency> families,
                                   const FaultBandOptions& opt) {
  opt.validate();
  std::vector<FaultBand> bands;
  for (std::size_t i = 0; i < families.size(); ++i) {
    const FaultFrequency& fam = families[i];
    const std::string field = "families[" + std::to_string(i) + "]";
    if (!(fam.frequency_hz > 0) || !std::isfinite(fam.frequency_hz))
      diag::fail_range("fault_bands", field + ".frequency_hz", fam.frequency_hz, "> 0");
    if (!(fam.sideband_hz >= 0) || !std::isfinite(fam.sideband_hz))
      diag::fail_range("fault_bands", field + ".sideband_hz", fam.sideband_hz, ">= 0");
    const double width = opt.width_hz > 0 ? opt.width_hz : 0.1 * fam.frequency_hz;
    const int k_max = fam.sideband_hz > 0 ? opt.sidebands : 0;
    for (int h = 1; h <= opt.harmonics; ++h) {
      for (int k = -k_max; k <= k_max; ++k) {
        const double centre = h * fam.frequency_hz + k * fam.sideband_hz;
        if (centre <= 0) continue;
        FaultBand b;
        b.label = band_label(fam.label, h, k);
        b.family = static_cast<int>(i);
        b.harmonic = h;
        b.sideband = k;
        b.centre_hz = centre;
        b.low_hz = std::max(0.0, centre - 0.5 * width);
        b.high_hz = centre + 0.5 * width;
        bands.push_back(std::move(b));
      }
    }
  }
  return bands;
}

std::vector<FaultFrequency> bearing_fault_families(const BearingFrequencies& f) {
  return {{"FTF", f.ftf_hz, 0.0},
          {"BPFO", f.bpfo_hz, 0.0},
          {"BPFI", f.bpfi_hz, f.shaft_hz},
          {"BALL", f.ball_fault_hz, f.ftf_hz}};
}

std::vector<FaultBand> bearing_fault_bands(const BearingFrequencies& f,
                                           const FaultBandOptions& opt) {
  const std::vector<FaultFrequency> fam = bearing_fault_families(f);
  return fault_bands(fam, opt);
}

// ---- Metrics ------------------------------------------------------------------------------------

FaultBandMetrics fault_band_metrics(const SpectrumView& s, std::span<const FaultBand> bands,
                                    SpectrumScale scale) {
  s.validate("fault_band_metrics");
  FaultBandMetrics out;
  for (std::size_t k = 0; k < s.value.size(); ++k) out.total_energy += bin_energy(s, k, scale);
  out.bands.reserve(bands.size());
  for (const FaultBand& b : bands) {
    BandMetrics m;
    m.peak_frequency_hz = kNaN;
    const auto [first, last] = bins_between(s.frequency_hz, b.low_hz, b.high_hz);
    for (std::size_t k = first; k < last; ++k) {
      m.energy += bin_energy(s, k, scale);
      if (m.bins == 0 || s.value[k] > m.peak_value) {
        m.peak_value = s.value[k];
        m.peak_frequency_hz = s.frequency_hz[k];
      }
      ++m.bins;
    }
    m.energy_fraction = out.total_energy > 0 ? m.energy / out.total_energy : 0.0;
    out.total_band_energy += m.energy;
    out.bands.push_back(m);
  }
  return out;
}

// ---- Lines --------------------------------------------------------------------------------------

double precision_floor(const SpectrumView& s, double dynamic_range_db) {
  if (!(dynamic_range_db > 0 && dynamic_range_db <= kMaxProminenceDb))
    diag::fail_range("precision_floor", "dynamic_range_db", dynamic_range_db, "(0, 300]");
  double top = 0;
  for (double v : s.value) top = std::max(top, v);
  return top * std::pow(10.0, -dynamic_range_db / 20.0);
}

LineMeasurement measure_line(const SpectrumView& s, double expected_hz, double search_hw,
                             double floor_hw, double min_floor) {
  if (!(search_hw >= 0) || !(floor_hw > search_hw))
    throw InputError(diag::format_error("measure_line", "floor_halfwidth_hz",
                                        "must exceed search_halfwidth_hz >= 0 (got " +
                                            std::to_string(floor_hw) + " and " +
                                            std::to_string(search_hw) + ")"));
  if (!(min_floor >= 0) || !std::isfinite(min_floor))
    diag::fail_range("measure_line", "min_floor", min_floor, "finite, >= 0");
  LineMeasurement m;
  m.expected_hz = expected_hz;
  const auto& f = s.frequency_hz;
  if (expected_hz - search_hw < f.front() || expected_hz + search_hw > f.back()) return m;
  const auto [first, last] = bins_between(f, expected_hz - search_hw, expected_hz + search_hw);
  std::size_t best = first;
  if (first == last) {
    // Window narrower than a bin: take the nearest bin.
    best = first < f.size() && (first == 0 || f[first] - expected_hz < expected_hz - f[first - 1])
               ? first
               : first - 1;
  } else {
    for (std::size_t k = first; k < last; ++k)
      if (s.value[k] > s.value[best]) best = k;
  }
  m.frequency_hz = f[best];
  m.amplitude = s.value[best];

  // Floor: the bins of [expected - floor_hw, expected + floor_hw] outside the search window (and
  // outside the chosen bin). A median of at most a few hundred values: a small stack-free buffer
  // would do, but thread_local scratch keeps measure_line allocation-free after the first call.
  thread_local std::vector<double> scratch;
  scratch.clear();
  const auto [lo_first, lo_last] = bins_between(f, expected_hz - floor_hw, expected_hz + floor_hw);
  for (std::size_t k = lo_first; k < lo_last; ++k) {
    if ((k >= first && k < last) || k == best) continue;
    scratch.push_back(s.value[k]);
  }
  if (scratch.size() < 3) return m;
  const std::size_t mid = scratch.size() / 2;
  std::nth_element(scratch.begin(), scratch.begin() + static_cast<std::ptrdiff_t>(mid),
                   scratch.end());
  double median = scratch[mid];
  if (scratch.size() % 2 == 0) {
    const double below =
        *std::max_element(scratch.begin(), scratch.begin() + static_cast<std::ptrdiff_t>(mid));
    median = 0.5 * (median + below);
  }
  m.local_floor = median;
  m.floor = std::max(median, min_floor);
  m.valid = true;
  if (m.amplitude <= 0) {
    m.prominence_db = m.floor > 0 ? -kMaxProminenceDb : 0.0;
  } else if (m.floor <= 0) {
    m.prominence_db = kMaxProminenceDb;
  } else {
    m.prominence_db =
        std::clamp(20.0 * std::log10(m.amplitude / m.floor), -kMaxProminenceDb, kMaxProminenceDb);
  }
  return m;
}

// ---- Bearing decision ---------------------------------------------------------------------------

diag::FaultKind fault_kind(BearingFault f) {
  switch (f) {
    case BearingFault::kCage:
      return diag::FaultKind::kCage;
    case BearingFault::kOuterRace:
      return diag::FaultKind::kOuterRace;
    case BearingFault::kInnerRace:
      return diag::FaultKind::kInnerRace;
    case BearingFault::kRollingElement:
      return diag::FaultKind::kRollingElement;
    case BearingFault::kNone:
      break;
  }
  return diag::FaultKind::kNone;
}

const char* to_string(BearingFault f) { return diag::to_string(fault_kind(f)).data(); }

const char* to_string(BearingDecisionStatus s) {
  switch (s) {
    case BearingDecisionStatus::kNoFault:
      return "no_fault";
    case BearingDecisionStatus::kFault:
      return "fault";
    case BearingDecisionStatus::kAmbiguous:
      return "ambiguous";
  }
  return "unknown";
}

void BearingDecisionOptions::validate() const {
  const std::string w = "BearingDecisionOptions";
  if (harmonics < 1 || harmonics > 20) diag::fail_range(w, "harmonics", harmonics, "1..20");
  if (min_harmonics < 1 || min_harmonics > harmonics)
    diag::fail_range(w, "min_harmonics", min_harmonics, "1..harmonics");
  if (!(slip_fraction >= 0 && slip_fraction <= 0.1))
    diag::fail_range(w, "slip_fraction", slip_fraction, "[0, 0.1]");
  if (search_bins < 0 || search_bins > 50) diag::fail_range(w, "search_bins", search_bins, "0..50");
  if (floor_bins < 3) diag::fail_range(w, "floor_bins", floor_bins, ">= 3");
  if (!(line_threshold_db > 0)) diag::fail_range(w, "line_threshold_db", line_threshold_db, "> 0");
  if (!(score_threshold_db > 0))
    diag::fail_range(w, "score_threshold_db", score_threshold_db, "> 0");
  if (!(margin_db >= 0)) diag::fail_range(w, "margin_db", margin_db, ">= 0");
  if (!(sideband_threshold_db > 0))
    diag::fail_range(w, "sideband_threshold_db", sideband_threshold_db, "> 0");
  if (!(dynamic_range_db > line_threshold_db && dynamic_range_db <= kMaxProminenceDb))
    diag::fail_range(w, "dynamic_range_db", dynamic_range_db, "(line_threshold_db, 300]");
  if (support_harmonics < 2 || support_harmonics > 50)
    diag::fail_range(w, "support_harmonics", support_harmonics, "2..50");
  if (support_surrogates < 9 || support_surrogates > 500)
    diag::fail_range(w, "support_surrogates", support_surrogates, "9..500");
  if (!(support_max_detune > 0 && support_max_detune <= 0.5))
    diag::fail_range(w, "support_max_detune", support_max_detune, "(0, 0.5]");
}

namespace {

double bin_spacing(const SpectrumView& env) {
  const auto& fr = env.frequency_hz;
  return (fr.back() - fr.front()) / static_cast<double>(fr.size() - 1);
}

// The lines of one family (see the header's scoring).
FamilyScore score_family(const SpectrumView& env, BearingFault fault, double f0, double df,
                         double min_floor, const BearingDecisionOptions& opt) {
  FamilyScore fs;
  fs.fault = fault;
  fs.fundamental_hz = f0;
  double sum_db = 0;
  for (int h = 1; h <= opt.harmonics; ++h) {
    const double centre = h * f0;
    const double search = std::max(opt.search_bins * df, opt.slip_fraction * centre);
    const LineMeasurement m =
        measure_line(env, centre, search, search + opt.floor_bins * df, min_floor);
    if (m.valid && m.prominence_db >= opt.line_threshold_db) {
      ++fs.detected;
      sum_db += m.prominence_db;
    }
    fs.lines.push_back(m);
  }
  fs.score_db = sum_db / opt.harmonics;
  fs.lines_pass = fs.detected >= opt.min_harmonics && fs.score_db >= opt.score_threshold_db;
  return fs;
}

// Sidebands at +-spacing around every detected line of `fs`, searched within +-search_bins bins
// of the found line's frequency +- spacing (the spacing is a rate of its own, not slipped with
// the carrier's harmonic number).
void measure_sidebands(const SpectrumView& env, FamilyScore& fs, double spacing, double df,
                       double min_floor, const BearingDecisionOptions& opt) {
  fs.sideband_hz = spacing;
  if (!(spacing > 0)) return;
  const double search = std::max(1, opt.search_bins) * df;
  // Keep the sideband's floor window off the carrier: at most half the spacing wide each side.
  const double floor_hw =
      std::max(search + 3 * df, std::min(search + opt.floor_bins * df, spacing - search));
  for (const LineMeasurement& line : fs.lines) {
    if (!(line.valid && line.prominence_db >= opt.line_threshold_db)) continue;
    for (int side : {-1, 1}) {
      const LineMeasurement m =
          measure_line(env, line.frequency_hz + side * spacing, search, floor_hw, min_floor);
      if (m.valid && m.prominence_db >= opt.sideband_threshold_db) ++fs.sidebands_detected;
      fs.sidebands.push_back(m);
    }
  }
}

// Whether family a's modulation signature explains family b's lines (see the header).
bool explains(const FamilyScore& a, const FamilyScore& b) {
  using F = BearingFault;
  if (a.fault == F::kRollingElement && b.fault == F::kInnerRace)
    return a.sidebands_detected >= 2 && a.modulation_lines >= 1 && b.sidebands_detected <= 1;
  if (a.fault == F::kRollingElement && b.fault == F::kOuterRace)
    return a.sidebands_detected >= 2 && a.modulation_lines >= 2;
  if (a.fault == F::kInnerRace && b.fault == F::kRollingElement)
    return a.sidebands_detected >= 2 && b.sidebands_detected == 0;
  return false;
}

}  // namespace

double found_fundamental(const FamilyScore& family, double line_threshold_db) {
  double num = 0, den = 0;
  for (std::size_t i = 0; i < family.lines.size(); ++i) {
    const LineMeasurement& m = family.lines[i];
    if (!(m.valid && m.prominence_db >= line_threshold_db)) continue;
    num += m.frequency_hz;
    den += static_cast<double>(i + 1);
  }
  return den > 0 ? num / den : family.fundamental_hz;
}

BearingDecision diagnose_bearing_from_envelope(const SpectrumView& env, const BearingFrequencies& f,
                                               const BearingDecisionOptions& opt) {
  opt.validate();
  env.validate("diagnose_bearing");
  const double df = bin_spacing(env);
  const double min_floor = precision_floor(env, opt.dynamic_range_db);

  BearingDecision d;
  const std::pair<BearingFault, double> fams[] = {{BearingFault::kCage, f.ftf_hz},
                                                  {BearingFault::kOuterRace, f.bpfo_hz},
                                                  {BearingFault::kInnerRace, f.bpfi_hz},
                                                  {BearingFault::kRollingElement, f.ball_fault_hz}};
  int ftf_detected = 0;
  bool ftf_lines_pass = false;
  for (const auto& [fault, f0] : fams) {
    if (fault == BearingFault::kCage && !opt.include_cage) continue;
    FamilyScore fs = score_family(env, fault, f0, df, min_floor, opt);
    switch (fault) {
      case BearingFault::kCage:
        ftf_detected = fs.detected;
        ftf_lines_pass = fs.lines_pass;
        fs.passes = false;  // never a finding on its own
        break;
      case BearingFault::kInnerRace:
        measure_sidebands(env, fs, f.shaft_hz, df, min_floor, opt);
        fs.passes = fs.lines_pass;
        break;
      case BearingFault::kRollingElement:
        measure_sidebands(env, fs, f.ftf_hz, df, min_floor, opt);
        fs.modulation_lines = ftf_detected;
        fs.passes = fs.lines_pass && fs.sidebands_detected + fs.modulation_lines >= 1;
        d.unmodulated_ball = fs.lines_pass && !fs.passes;
        break;
      default:
        fs.passes = fs.lines_pass;
    }
    d.families.push_back(std::move(fs));
  }

  // A passing family whose lines another passing family's modulation explains is set aside.
  for (FamilyScore& b : d.families) {
    if (!b.passes) continue;
    for (const FamilyScore& a : d.families)
      if (&a != &b && a.passes && explains(a, b) && !explains(b, a)) b.explained = true;
  }
  const FamilyScore* best = nullptr;
  for (const FamilyScore& fs : d.families) {
    if (!fs.passes || fs.explained) continue;
    d.candidates.push_back(fs.fault);
    if (best == nullptr || fs.score_db > best->score_db) best = &fs;
  }
  if (best == nullptr) {
    // Ball lines without their modulation: evidence of something, of no part we can name.
    if (d.unmodulated_ball) d.status = BearingDecisionStatus::kAmbiguous;
    d.cage_note = ftf_lines_pass && !d.unmodulated_ball;
    return d;
  }
  for (const FamilyScore& fs : d.families) {
    if (&fs != best && fs.passes && !fs.explained && best->score_db - fs.score_db < opt.margin_db) {
      d.status = BearingDecisionStatus::kAmbiguous;
      return d;
    }
  }
  d.status = BearingDecisionStatus::kFault;
  d.fault = best->fault;
  return d;
}

namespace {

// Mean over h = 1..K of the clipped prominence at h f0 (see comb_support); K reduced to the
// harmonics whose windows fit in the spectrum.
double comb_statistic(const SpectrumView& s, double f0, int k_max, double df, double min_floor,
                      int floor_bins, int* used) {
  constexpr double kClipDb = 20.0;  // one foreign line cannot carry the comb
  double sum = 0;
  int n = 0;
  for (int h = 1; h <= k_max; ++h) {
    const double search = df * (1.0 + 0.25 * h);
    const LineMeasurement m = measure_line(s, h * f0, search, search + floor_bins * df, min_floor);
    if (!m.valid) break;
    sum += std::clamp(m.prominence_db, -kClipDb, kClipDb);
    ++n;
  }
  if (used != nullptr) *used = n;
  return n > 0 ? sum / n : 0.0;
}

}  // namespace

CombSupport comb_support(const SpectrumView& s, double f0, const BearingDecisionOptions& opt) {
  opt.validate();
  s.validate("comb_support");
  if (!(f0 > 0) || !std::isfinite(f0))
    diag::fail_range("comb_support", "fundamental_hz", f0, "> 0");
  const double df = bin_spacing(s);
  const double min_floor = precision_floor(s, opt.dynamic_range_db);
  CombSupport c;
  c.fundamental_hz = f0;
  c.statistic_db =
      comb_statistic(s, f0, opt.support_harmonics, df, min_floor, opt.floor_bins, &c.harmonics);
  if (c.harmonics < 2) return c;
  std::vector<double> null;
  const int m = opt.support_surrogates;
  const double d_min = opt.support_max_detune / 5;
  for (int i = 0; i < m; ++i) {
    // Alternate below and above f0, detunings spread evenly over [d_min, d_max].
    const double d = d_min + (opt.support_max_detune - d_min) * (i / 2) / std::max(1, (m - 1) / 2);
    const double fs = f0 * (i % 2 == 0 ? 1 - d : 1 + d);
    null.push_back(comb_statistic(s, fs, c.harmonics, df, min_floor, opt.floor_bins, nullptr));
  }
  c.null_max_db = *std::max_element(null.begin(), null.end());
  std::nth_element(null.begin(), null.begin() + m / 2, null.end());
  c.null_median_db = null[static_cast<std::size_t>(m / 2)];
  c.supported = c.statistic_db > c.null_max_db && c.statistic_db > 0;
  return c;
}

}  // namespace detect
