#include "detect/bearing/bearing_diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "detect/spectral/envelope.hpp"
#include "detect/spectral/fft.hpp"
#include "detect/spectral/kurtogram.hpp"
#include "detect/spectral/spectrum.hpp"
#include "diag/error.hpp"

namespace detect {

namespace {

// The prefix of its error messages (they reach the analysis report's channel notes, so it stays
// the short name).
constexpr const char* kWhere = "diagnose_bearings";

// The record to diagnose: x_w = IDFT(X / |X|) with DC removed (prewhiten; bins with |X_k| below
// 1e-12 max|X|, nothing there to whiten, are set to 0 rather than blown up to unit magnitude), or
// x with its mean removed; `spectrum` receives its DFT (the squared envelope spectra start from
// it).
std::vector<double> diagnosed_record(std::span<const double> x, bool prewhiten,
                                     std::vector<std::complex<double>>& spectrum) {
  RealFft fft(x.size());
  std::vector<std::complex<double>>& X = spectrum;
  X.resize(fft.bins());
  fft.forward(x, X);
  double peak = 0;
  if (prewhiten) {
    for (const auto& v : X) peak = std::max(peak, std::abs(v));
  }
  X[0] = 0;  // the mean
  if (prewhiten) {
    const double tiny = 1e-12 * peak;
    for (std::size_t k = 1; k < X.size(); ++k) {
      const double a = std::abs(X[k]);
      X[k] = a > tiny ? X[k] / a : std::complex<double>(0.0);
    }
  }
  std::vector<double> y(x.size());
  if (prewhiten) {
    fft.inverse(X, y);
  } else {
    double mean = 0;
    for (double v : x) mean += v;
    mean /= static_cast<double>(x.size());
    for (std::size_t j = 0; j < x.size(); ++j) y[j] = x[j] - mean;
  }
  return y;
}

const FamilyScore* family(const BearingDecision& d, BearingFault f) {
  for (const FamilyScore& s : d.families)
    if (s.fault == f) return &s;
  return nullptr;
}

const char* family_label(BearingFault f) {
  switch (f) {
    case BearingFault::kOuterRace:
      return "BPFO";
    case BearingFault::kInnerRace:
      return "BPFI";
    case BearingFault::kRollingElement:
      return "2xBSF";
    case BearingFault::kCage:
      return "FTF";
    default:
      return "";
  }
}

// Combined decision (see the header). `band` and `whole` are the two views' spectra.
void combine(BearingStatus& s, bool whole_checked, const SpectrumView& band,
             const SpectrumView& whole, const BearingDiagnosisOptions& options) {
  const BearingDecisionOptions& opt = options.decision;
  const BearingDecision& a = s.band_decision;
  if (!whole_checked) {
    s.status = a.status;
    s.fault = a.fault;
    if (a.cage_note) s.note = "cage";
    return;
  }
  const BearingDecision& b = s.whole_decision;
  using St = BearingDecisionStatus;
  if (a.status == St::kFault && b.status == St::kFault && a.fault == b.fault) {
    s.status = St::kFault;
    s.fault = a.fault;
  } else if (a.status == St::kNoFault && b.status == St::kNoFault) {
    s.status = St::kNoFault;
    if (a.cage_note && b.cage_note) s.note = "cage";
  } else if ((a.status == St::kFault && b.status == St::kNoFault) ||
             (a.status == St::kNoFault && b.status == St::kFault)) {
    // One view names F, the other nothing: F's comb must stand in the other view.
    const bool band_names = a.status == St::kFault;
    const BearingDecision& naming = band_names ? a : b;
    const FamilyScore* fam = family(naming, naming.fault);
    s.status = St::kAmbiguous;
    if (fam->detected == static_cast<int>(fam->lines.size()) &&
        fam->score_db >= options.single_view_score_db) {
      const double f0 = found_fundamental(*fam, opt.line_threshold_db);
      s.support = comb_support(band_names ? whole : band, f0, opt);
      if (s.support.supported) {
        s.status = St::kFault;
        s.fault = naming.fault;
      }
    }
  } else {
    s.status = St::kAmbiguous;  // conflicting names, a tie, or unmodulated ball lines
  }
}

BearingEvidence evidence(const BearingStatus& s) {
  using St = BearingDecisionStatus;
  BearingEvidence e;
  e.family = family_label(s.fault);
  const bool band_names = s.band_decision.status == St::kFault;
  const BearingDecision& naming = band_names ? s.band_decision : s.whole_decision;
  const BearingDecision& other = band_names ? s.whole_decision : s.band_decision;
  const bool both = s.band_decision.status == St::kFault && s.whole_decision.status == St::kFault;
  e.basis = both ? "both_views" : band_names ? "band_view_comb_support" : "whole_view_comb_support";
  if (const FamilyScore* f = family(naming, s.fault)) {
    e.harmonics_seen = f->detected;
    e.harmonics_scored = static_cast<int>(f->lines.size());
    for (const LineMeasurement& m : f->lines) e.line_db.push_back(m.valid ? m.prominence_db : 0.0);
    e.sideband_hz = f->sideband_hz;
    e.sidebands_seen = f->sidebands_detected;
    e.ftf_lines_seen = f->modulation_lines;
  }
  if (const FamilyScore* f = family(other, s.fault)) e.other_view_score_db = f->score_db;
  if (!both) {
    e.support_db = s.support.statistic_db;
    e.support_null_db = s.support.null_max_db;
  }
  return e;
}

nlohmann::json families_json(const BearingDecision& d) {
  nlohmann::json a = nlohmann::json::array();
  for (const FamilyScore& f : d.families) {
    nlohmann::json lines = nlohmann::json::array();
    for (const LineMeasurement& m : f.lines) lines.push_back(m.valid ? m.prominence_db : 0.0);
    a.push_back({{"fault", finding_name(f.fault)},
                 {"family", family_label(f.fault)},
                 {"fundamental_hz", f.fundamental_hz},
                 {"score_db", f.score_db},
                 {"detected", f.detected},
                 {"line_db", lines},
                 {"sideband_hz", f.sideband_hz},
                 {"sidebands_detected", f.sidebands_detected},
                 {"modulation_lines", f.modulation_lines},
                 {"lines_pass", f.lines_pass},
                 {"passes", f.passes}});
  }
  return a;
}

// The evidence's numbers, as a finding carries them (finding.hpp).
std::vector<std::pair<std::string, double>> evidence_numbers(const BearingEvidence& e) {
  return {{"harmonics_seen", e.harmonics_seen}, {"harmonics_scored", e.harmonics_scored},
          {"sideband_hz", e.sideband_hz},       {"sidebands_seen", e.sidebands_seen},
          {"ftf_lines_seen", e.ftf_lines_seen}, {"other_view_score_db", e.other_view_score_db},
          {"support_db", e.support_db},         {"support_null_db", e.support_null_db}};
}

nlohmann::json evidence_json(const BearingEvidence& e) {
  nlohmann::json j = {{"family", e.family}, {"basis", e.basis}, {"line_db", e.line_db}};
  for (const auto& [key, value] : evidence_numbers(e)) j[key] = value;
  // Counts stay integers.
  for (const char* key : {"harmonics_seen", "harmonics_scored", "sidebands_seen", "ftf_lines_seen"})
    j[key] = static_cast<int>(j[key].get<double>());
  return j;
}

}  // namespace

void BearingDiagnosisOptions::validate() const {
  if (kurtogram_max_level < 1 || kurtogram_max_level > 20)
    diag::fail(kWhere, "kurtogram_max_level",
               std::to_string(kurtogram_max_level) + " is not in [1, 20]");
  if (!(min_bandwidth_factor >= 0 && min_bandwidth_factor <= 10))
    diag::fail(kWhere, "min_bandwidth_factor",
               std::to_string(min_bandwidth_factor) + " is not in [0, 10]");
  if (!(min_band_low_factor >= 0 && min_band_low_factor <= 100))
    diag::fail(kWhere, "min_band_low_factor",
               std::to_string(min_band_low_factor) + " is not in [0, 100]");
  if (!(single_view_score_db > 0))
    diag::fail(kWhere, "single_view_score_db",
               std::to_string(single_view_score_db) + " is not > 0");
  decision.validate();
}

const char* finding_name(BearingFault f) {
  // The fault vocabulary's names (diag/faults/fault_kind.hpp), "" for no fault.
  return f == BearingFault::kNone ? "" : to_string(f);
}

BearingDiagnosis diagnose_bearings_from_signal(const diag::Signal& channel, double shaft_hz,
                                               std::span<const diag::BearingSpec> bearings,
                                               const BearingDiagnosisOptions& options) {
  options.validate();
  diag::validate(channel, kWhere);
  if (!(shaft_hz > 0) || !std::isfinite(shaft_hz))
    diag::fail(kWhere, "shaft_hz", std::to_string(shaft_hz) + " is not finite and > 0");
  if (bearings.empty()) diag::fail(kWhere, "bearings", "none given");
  const double fs = channel.fs_hz;

  BearingDiagnosis out;
  out.channel = channel.name;
  double f_max = 0;
  for (const diag::BearingSpec& b : bearings) {
    BearingStatus s;
    s.bearing = b.name;
    s.frequencies = bearing_frequencies(b, shaft_hz);
    f_max = std::max(
        {f_max, s.frequencies.bpfi_hz, s.frequencies.ball_fault_hz, s.frequencies.bpfo_hz});
    out.bearings.push_back(std::move(s));
  }

  std::vector<std::complex<double>> X;
  const std::vector<double> x =
      diagnosed_record(fast_length_middle(channel.samples), options.prewhiten, X);
  const std::size_t n = x.size();

  const double min_bw = options.min_bandwidth_factor * options.decision.harmonics * f_max;
  const double min_low = options.min_band_low_factor * f_max;
  KurtogramOptions ko;
  ko.fs_hz = fs;
  ko.max_level = options.kurtogram_max_level;
  ko.min_bandwidth_hz = min_bw;  // only the allowed bands are computed
  ko.min_low_hz = min_low;
  const Kurtogram kg = fast_kurtogram(x, ko);
  bool found = false;
  for (const KurtogramLevel& lvl : kg.levels) {
    if (lvl.bandwidth_hz < min_bw) continue;
    for (std::size_t i = 0; i < lvl.kurtosis.size(); ++i) {
      const double low = static_cast<double>(i) * lvl.bandwidth_hz;
      if (low < min_low) continue;
      if (!found || lvl.kurtosis[i] > out.band_kurtosis) {
        found = true;
        out.band_kurtosis = lvl.kurtosis[i];
        out.band_centre_hz = low + 0.5 * lvl.bandwidth_hz;
        out.band_width_hz = lvl.bandwidth_hz;
        out.band_level = lvl.level;
      }
    }
  }
  if (!found)
    diag::fail(kWhere, "channel " + channel.name,
               "no kurtogram band is at least " + std::to_string(min_bw) + " Hz wide and above " +
                   std::to_string(min_low) + " Hz at fs = " + std::to_string(fs) +
                   " Hz: the sampling rate is too low for these fault frequencies");

  const double low = out.band_centre_hz - 0.5 * out.band_width_hz;
  const double high = std::min(out.band_centre_hz + 0.5 * out.band_width_hz, 0.5 * fs);
  const Spectrum band_ses = squared_envelope_spectrum(X, n, {fs, low, high});
  Spectrum whole_ses;
  if (options.whole_band_check)
    whole_ses = squared_envelope_spectrum(X, n, {fs, 0.0, 0.5 * fs}, WindowType::kHann, x);

  const SpectrumView band_view{band_ses.frequency_hz, band_ses.amplitude};
  const SpectrumView whole_view{whole_ses.frequency_hz, whole_ses.amplitude};
  for (BearingStatus& s : out.bearings) {
    s.band_decision = diagnose_bearing_from_envelope(band_view, s.frequencies, options.decision);
    if (options.whole_band_check)
      s.whole_decision =
          diagnose_bearing_from_envelope(whole_view, s.frequencies, options.decision);
    combine(s, options.whole_band_check, band_view, whole_view, options);
    if (s.status != BearingDecisionStatus::kFault) continue;
    s.evidence = evidence(s);
    Finding f;
    f.kind = "bearing";
    f.fault = fault_kind(s.fault);
    f.bearing = s.bearing;
    f.channel = channel.name;
    const FamilyScore* fam = family(s.band_decision, s.fault);
    const FamilyScore* whole =
        options.whole_band_check ? family(s.whole_decision, s.fault) : nullptr;
    f.frequency_hz = fam != nullptr ? fam->fundamental_hz : 0.0;
    // Both views name it: sure; one view with the comb's support in the other: half as sure.
    f.confidence = s.evidence.basis == "both_views" ? 1.0 : 0.5;
    const BearingEvidence& e = s.evidence;
    f.evidence = evidence_numbers(e);
    f.evidence.insert(f.evidence.begin(),
                      {"score_db", std::max(fam != nullptr ? fam->score_db : 0.0,
                                            whole != nullptr ? whole->score_db : 0.0)});
    f.note = e.family + " (" + e.basis + ")";
    out.findings.push_back(std::move(f));
  }
  out.band_ses_frequency_hz = band_ses.frequency_hz;
  out.band_ses_amplitude = band_ses.amplitude;
  return out;
}

nlohmann::json to_json(const BearingDiagnosis& d) {
  nlohmann::json j;
  j["channel"] = d.channel;
  j["band"] = {{"centre_hz", d.band_centre_hz},
               {"bandwidth_hz", d.band_width_hz},
               {"level", d.band_level},
               {"kurtosis", d.band_kurtosis}};
  nlohmann::json findings = nlohmann::json::array();
  for (const Finding& f : d.findings) {
    nlohmann::json fj = to_json(f);
    // The module's own evidence object (family, basis, line_db: not only numbers) replaces the
    // generic one; the numbers stay at the top level.
    for (const BearingStatus& s : d.bearings) {
      if (s.bearing == f.bearing) fj["evidence"] = evidence_json(s.evidence);
    }
    findings.push_back(std::move(fj));
  }
  j["findings"] = findings;
  nlohmann::json bearings = nlohmann::json::array();
  for (const BearingStatus& s : d.bearings) {
    nlohmann::json b = {{"bearing", s.bearing},
                        {"status", to_string(s.status)},
                        {"fault", finding_name(s.fault)},
                        {"note", s.note},
                        {"families", families_json(s.band_decision)}};
    if (!s.whole_decision.families.empty())
      b["whole_band_families"] = families_json(s.whole_decision);
    if (s.support.harmonics > 0)
      b["comb_support"] = {
          {"fundamental_hz", s.support.fundamental_hz}, {"harmonics", s.support.harmonics},
          {"statistic_db", s.support.statistic_db},     {"null_max_db", s.support.null_max_db},
          {"null_median_db", s.support.null_median_db}, {"supported", s.support.supported}};
    bearings.push_back(b);
  }
  j["bearings"] = bearings;
  return j;
}

}  // namespace detect
