#include "detect/gear/bearing_diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <nlohmann/json.hpp>
#include <string>

#include "detect/spectral/envelope.hpp"
#include "detect/spectral/fft.hpp"
#include "detect/spectral/kurtogram.hpp"
#include "detect/spectral/spectrum.hpp"
#include "diag/error.hpp"

namespace detect {

namespace {

constexpr const char* kWhere = "diagnose_bearings";

[[noreturn]] void fail(const std::string& field, const std::string& reason) {
  throw diag::InputError(diag::format_error(kWhere, field, reason));
}

// x_w = IDFT(X / |X|), DC removed. Bins with |X_k| below 1e-12 max|X| (nothing there to whiten)
// are set to 0 rather than blown up to unit magnitude.
std::vector<double> cepstral_prewhiten(std::span<const double> x) {
  RealFft fft(x.size());
  std::vector<std::complex<double>> X(fft.bins());
  fft.forward(x, X);
  double peak = 0;
  for (const auto& v : X) peak = std::max(peak, std::abs(v));
  const double tiny = 1e-12 * peak;
  X[0] = 0;
  for (std::size_t k = 1; k < X.size(); ++k) {
    const double a = std::abs(X[k]);
    X[k] = a > tiny ? X[k] / a : std::complex<double>(0.0);
  }
  std::vector<double> y(x.size());
  fft.inverse(X, y);
  return y;
}

// Amplitude spectrum (Hann, peak scaling) of the squared envelope of x in [low, high], mean
// removed.
Spectrum squared_envelope_spectrum(std::span<const double> x, double fs_hz, double low_hz,
                                   double high_hz) {
  BandOptions band;
  band.fs_hz = fs_hz;
  band.low_hz = low_hz;
  band.high_hz = high_hz;
  std::vector<double> e = band_envelope(x, band);
  double mean = 0;
  for (double& v : e) {
    v *= v;
    mean += v;
  }
  mean /= static_cast<double>(e.size());
  for (double& v : e) v -= mean;
  SpectrumOptions so;
  so.fs_hz = fs_hz;
  so.window = WindowType::kHann;
  return amplitude_spectrum(e, so);
}

// Combined decision: see the header.
void combine(BearingStatus& s, bool whole_checked) {
  const BearingDecision& a = s.band_decision;
  if (!whole_checked) {
    s.status = a.status;
    s.fault = a.fault;
    return;
  }
  const BearingDecision& b = s.whole_decision;
  using St = BearingDecisionStatus;
  if (a.status == St::kFault && b.status == St::kFault && a.fault == b.fault) {
    s.status = St::kFault;
    s.fault = a.fault;
  } else if (a.status == St::kNoFault && b.status == St::kNoFault) {
    s.status = St::kNoFault;
  } else {
    s.status = St::kAmbiguous;  // evidence in one view only, conflicting names, or a tie
  }
}

const FamilyScore* family(const BearingDecision& d, BearingFault f) {
  for (const FamilyScore& s : d.families)
    if (s.fault == f) return &s;
  return nullptr;
}

nlohmann::json families_json(const BearingDecision& d) {
  nlohmann::json a = nlohmann::json::array();
  for (const FamilyScore& f : d.families)
    a.push_back({{"fault", finding_name(f.fault)},
                 {"fundamental_hz", f.fundamental_hz},
                 {"score_db", f.score_db},
                 {"detected", f.detected},
                 {"passes", f.passes}});
  return a;
}

}  // namespace

void BearingDiagnosisOptions::validate() const {
  if (kurtogram_max_level < 1 || kurtogram_max_level > 20)
    fail("kurtogram_max_level", std::to_string(kurtogram_max_level) + " is not in [1, 20]");
  if (!(min_bandwidth_factor >= 0 && min_bandwidth_factor <= 10))
    fail("min_bandwidth_factor", std::to_string(min_bandwidth_factor) + " is not in [0, 10]");
  if (!(min_band_low_factor >= 0 && min_band_low_factor <= 100))
    fail("min_band_low_factor", std::to_string(min_band_low_factor) + " is not in [0, 100]");
  decision.validate();
}

const char* finding_name(BearingFault f) {
  // to_string's names (fault_bands.hpp) but the findings' "rolling_element" and no "none".
  if (f == BearingFault::kNone) return "";
  if (f == BearingFault::kBall) return "rolling_element";
  return to_string(f);
}

BearingDiagnosis diagnose_bearings(const diag::Signal& channel, double shaft_hz,
                                   std::span<const diag::BearingSpec> bearings,
                                   const BearingDiagnosisOptions& options) {
  options.validate();
  diag::validate(channel, kWhere);
  if (!(shaft_hz > 0) || !std::isfinite(shaft_hz))
    fail("shaft_hz", std::to_string(shaft_hz) + " is not finite and > 0");
  if (bearings.empty()) fail("bearings", "none given");
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

  std::vector<double> x = channel.samples;
  if (options.prewhiten) {
    x = cepstral_prewhiten(x);
  } else {
    double mean = 0;
    for (double v : x) mean += v;
    mean /= static_cast<double>(x.size());
    for (double& v : x) v -= mean;
  }

  KurtogramOptions ko;
  ko.fs_hz = fs;
  ko.max_level = options.kurtogram_max_level;
  const Kurtogram kg = fast_kurtogram(x, ko);
  const double min_bw = options.min_bandwidth_factor * options.decision.harmonics * f_max;
  const double min_low = options.min_band_low_factor * f_max;
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
    fail("channel " + channel.name,
         "no kurtogram band is at least " + std::to_string(min_bw) + " Hz wide and above " +
             std::to_string(min_low) + " Hz at fs = " + std::to_string(fs) +
             " Hz: the sampling rate is too low for these fault frequencies");

  const double low = out.band_centre_hz - 0.5 * out.band_width_hz;
  const double high = std::min(out.band_centre_hz + 0.5 * out.band_width_hz, 0.5 * fs);
  const Spectrum band_ses = squared_envelope_spectrum(x, fs, low, high);
  Spectrum whole_ses;
  if (options.whole_band_check) whole_ses = squared_envelope_spectrum(x, fs, 0.0, 0.5 * fs);

  for (BearingStatus& s : out.bearings) {
    s.band_decision = diagnose_bearing({band_ses.frequency_hz, band_ses.amplitude}, s.frequencies,
                                       options.decision);
    if (options.whole_band_check)
      s.whole_decision = diagnose_bearing({whole_ses.frequency_hz, whole_ses.amplitude},
                                          s.frequencies, options.decision);
    combine(s, options.whole_band_check);
    if (s.status != BearingDecisionStatus::kFault) continue;
    BearingFinding f;
    f.bearing = s.bearing;
    f.fault = finding_name(s.fault);
    f.channel = channel.name;
    const FamilyScore* fam = family(s.band_decision, s.fault);
    const FamilyScore* whole =
        options.whole_band_check ? family(s.whole_decision, s.fault) : nullptr;
    f.frequency_hz = fam != nullptr ? fam->fundamental_hz : 0.0;
    f.score_db =
        std::max(fam != nullptr ? fam->score_db : 0.0, whole != nullptr ? whole->score_db : 0.0);
    out.findings.push_back(std::move(f));
  }
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
  for (const BearingFinding& f : d.findings)
    findings.push_back({{"bearing", f.bearing},
                        {"fault", f.fault},
                        {"frequency_hz", f.frequency_hz},
                        {"channel", f.channel},
                        {"score_db", f.score_db}});
  j["findings"] = findings;
  nlohmann::json bearings = nlohmann::json::array();
  for (const BearingStatus& s : d.bearings) {
    nlohmann::json b = {{"bearing", s.bearing},
                        {"status", to_string(s.status)},
                        {"fault", finding_name(s.fault)},
                        {"families", families_json(s.band_decision)}};
    if (!s.whole_decision.families.empty())
      b["whole_band_families"] = families_json(s.whole_decision);
    bearings.push_back(b);
  }
  j["bearings"] = bearings;
  return j;
}

}  // namespace detect
