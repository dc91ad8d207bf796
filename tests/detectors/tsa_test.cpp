#include "detect/angular/tsa.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "detect/angular/resample.hpp"
#include "diag/error.hpp"

namespace {

constexpr double kPi = std::numbers::pi;

struct Ramp {
  double phi0 = 0, f0 = 0, alpha = 0;
  double revs(double t) const { return phi0 + f0 * t + 0.5 * alpha * t * t; }
  double time_at(double r) const {
    const double c = phi0 - r;
    if (alpha == 0) return -c / f0;
    return (-f0 + std::sqrt(f0 * f0 - 2 * alpha * c)) / alpha;
  }
  std::vector<double> pulses(double duration) const {
    std::vector<double> t;
    for (long k = static_cast<long>(std::ceil(phi0));; ++k) {
      const double tk = time_at(static_cast<double>(k));
      if (tk > duration) break;
      if (tk >= 0) t.push_back(tk);
    }
    return t;
  }
};

// A shaft-synchronous waveform: shaft orders 1 and 3, mesh orders 27 and 54 (27 teeth).
double synchronous(double theta_rev) {
  return 0.4 * std::cos(2 * kPi * theta_rev + 0.2) + 0.15 * std::sin(2 * kPi * 3 * theta_rev) +
         1.0 * std::cos(2 * kPi * 27 * theta_rev + 1.1) + 0.3 * std::cos(2 * kPi * 54 * theta_rev);
}

double rms_error(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(s / static_cast<double>(a.size()));
}

// Truth on the TSA's grid: sample j at angle first_rev + j / spr from the first pulse.
std::vector<double> truth_on_grid(const detect::Tsa& t, double phase0) {
  std::vector<double> out(t.samples.size());
  for (std::size_t j = 0; j < out.size(); ++j) {
    out[j] = synchronous(phase0 + t.first_rev + static_cast<double>(j) / t.samples_per_rev);
  }
  return out;
}

// At constant speed a tone at order q is multiplied by the comb response
// D = |sin(pi N q) / (N sin(pi q))| (McFadden 1987): the TSA holds the synchronous waveform plus
// a residue of amplitude exactly D. Both are checked to the resampling ripple (kTol = 5e-4,
// resample_test's passband tolerance).
TEST(Tsa, AveragesOutANonSynchronousToneAsTheCombResponsePredicts) {
  const double fs = 10e3, f = 25.0, q = 13.37;
  const Ramp r{0.3, f, 0.0};
  const double duration = 3.0;
  const auto p = r.pulses(duration);
  std::vector<double> x(static_cast<std::size_t>(duration * fs)), tone(x.size());
  for (std::size_t n = 0; n < x.size(); ++n) {
    const double th = r.revs(n / fs);
    tone[n] = std::cos(2 * kPi * q * th);
    x[n] = synchronous(th) + tone[n];
  }
  detect::TsaOptions opt;
  opt.samples_per_rev = 256;
  const auto t = detect::tsa(x, fs, p, opt);
  const auto t_tone = detect::tsa(tone, fs, p, opt);
  const int n_rev = t.revolutions;
  EXPECT_GE(n_rev, 70);
  const double comb = std::abs(std::sin(kPi * n_rev * q) / (n_rev * std::sin(kPi * q)));
  constexpr double kTol = 5e-4;
  double peak = 0;
  for (double v : t_tone.samples) peak = std::max(peak, std::abs(v));
  // The residue is a cosine of order q over one revolution: its peak is D (to the sampling
  // of its maximum over 256 points, cos(pi q / 256) ~ 1 - 1e-3 at worst: use a one-sided check).
  EXPECT_LE(peak, comb + kTol);
  EXPECT_GE(peak, comb * std::cos(kPi * q / 256) - kTol);
  EXPECT_LT(comb, 0.02);  // the tone is suppressed to ~ 1 / N
  // Synchronous part kept: TSA minus the tone's residue equals the waveform.
  const double phase0 = r.revs(p.front());
  const auto truth = truth_on_grid(t, phase0);
  for (std::size_t j = 0; j < truth.size(); ++j) {
    EXPECT_NEAR(t.samples[j] - t_tone.samples[j], truth[j], kTol) << j;
  }
}

// Under a run-up (20 -> 30 rev/s) the TSA recovers the synchronous waveform, and the noise left
// in it falls as 1/sqrt(N). The reference is the noise level of the resampled record itself
// (sigma_r, before averaging), so sigma_r / sqrt(N) is the expected RMS error after N
// revolutions; checked within 25 % for N = 16 and N = 256. Why 25 %: the RMS of ~180
// independent values (the band-limited noise over 256 samples of one revolution has ~0.72 x 256
// degrees of freedom) scatters by 1/sqrt(2 x 180) = 5 %; 25 % is five of those.
TEST(Tsa, KeepsTheSynchronousPartUnderARunUpAndNoiseFallsAsOneOverSqrtN) {
  const double fs = 10e3, duration = 11.0, sigma = 0.5;
  const Ramp r{0.7, 20.0, 10.0 / duration};
  const auto p = r.pulses(duration);
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<double> x(static_cast<std::size_t>(duration * fs));
  for (std::size_t n = 0; n < x.size(); ++n) x[n] = synchronous(r.revs(n / fs)) + noise(rng);

  detect::ResampleOptions ro;
  ro.samples_per_rev = 256;
  const auto y = detect::resample_by_angle(x, fs, p, ro);
  ASSERT_GE(y.revolutions, 256);
  const double phase0 = r.revs(p.front());
  double s2 = 0;
  for (std::size_t m = 0; m < y.samples.size(); ++m) {
    const double d =
        y.samples[m] - synchronous(phase0 + y.first_rev + static_cast<double>(m) / 256);
    s2 += d * d;
  }
  const double sigma_r = std::sqrt(s2 / static_cast<double>(y.samples.size()));

  for (int n : {16, 256}) {
    detect::AngleResampled part = y;
    part.revolutions = n;
    part.samples.resize(static_cast<std::size_t>(n) * 256);
    const auto t = detect::tsa(part, 10);
    EXPECT_EQ(t.revolutions, n);
    const double err = rms_error(t.samples, truth_on_grid(t, phase0));
    const double expected = sigma_r / std::sqrt(n);
    EXPECT_GT(err, expected / 1.25) << "N = " << n;
    EXPECT_LT(err, expected * 1.25) << "N = " << n;
  }
  // The one-call form gives the same as resample + average.
  detect::TsaOptions opt;
  opt.samples_per_rev = 256;
  const auto direct = detect::tsa(x, fs, p, opt);
  const auto via = detect::tsa(y, 10);
  EXPECT_EQ(direct.samples, via.samples);
}

// The TSA of the countershaft (ratio 49/51 to the shaft with the tacho) from scaled pulses:
// its revolutions fall between the tacho's pulses. Its waveform comes back to the resampling
// ripple (5e-4), at the phase of the tacho's first pulse (scale_pulses' documented zero).
TEST(Tsa, OfAnotherShaftFromScaledPulsesRecoversThatShaftsWaveform) {
  const double fs = 10e3, duration = 6.0, ratio = 49.0 / 51.0;
  const Ramp a{0.25, 18.0, 2.0};
  const auto pa = a.pulses(duration);
  const double a0 = a.revs(pa.front());
  std::vector<double> x(static_cast<std::size_t>(duration * fs));
  for (std::size_t n = 0; n < x.size(); ++n) x[n] = synchronous(ratio * (a.revs(n / fs) - a0));
  const auto pb = detect::scale_pulses(pa, ratio);
  detect::TsaOptions opt;
  opt.samples_per_rev = 256;
  const auto t = detect::tsa(x, fs, pb, opt);
  const auto truth = truth_on_grid(t, 0.0);
  for (std::size_t j = 0; j < truth.size(); ++j) EXPECT_NEAR(t.samples[j], truth[j], 5e-4) << j;
}

// Several channels sharing one shaft's plan (what the analysis does for every channel of a
// recording) give the same bytes as the one-call form per channel.
TEST(Tsa, ThroughASharedPlanEqualsTheOneCallForm) {
  const double fs = 10e3, duration = 4.0;
  const Ramp r{0.3, 15.0, 3.0};
  const auto p = r.pulses(duration);
  std::vector<double> a(static_cast<std::size_t>(duration * fs)), b(a.size());
  for (std::size_t n = 0; n < a.size(); ++n) {
    a[n] = synchronous(r.revs(n / fs));
    b[n] = std::cos(2 * kPi * 77.3 * n / fs);
  }
  detect::TsaOptions opt;
  opt.samples_per_rev = 128;
  const auto plan = detect::make_angle_plan(p, fs, a.size(), opt.resample_options());
  for (const auto* x : {&a, &b}) {
    EXPECT_EQ(detect::tsa(*x, plan, opt.min_revolutions).samples,
              detect::tsa(*x, fs, p, opt).samples);
  }
}

TEST(Tsa, FewerRevolutionsThanRequiredIsAnErrorNamingTheField) {
  const double fs = 5e3;
  const Ramp r{0.5, 10.0, 0.0};
  const auto p = r.pulses(1.0);
  const std::vector<double> x(static_cast<std::size_t>(fs), 0.0);
  detect::TsaOptions opt;
  opt.samples_per_rev = 64;
  opt.min_revolutions = 20;
  try {
    detect::tsa(x, fs, p, opt);
    ADD_FAILURE() << "accepted";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("min_revolutions"), std::string::npos) << e.what();
  }
  opt.samples_per_rev = 100;
  EXPECT_THROW(opt.validate(), diag::InputError);
  opt.samples_per_rev = 32;
  EXPECT_THROW(opt.validate(), diag::InputError);
}

// ---- regular / residual / difference ------------------------------------------------------

// Amplitude of order k in a one-revolution record, by a naive DFT (independent of RealFft).
double naive_amplitude(const std::vector<double>& x, int k) {
  std::complex<double> acc = 0;
  const double n = static_cast<double>(x.size());
  for (std::size_t j = 0; j < x.size(); ++j) acc += x[j] * std::polar(1.0, -2 * kPi * k * j / n);
  return (k == 0 || 2 * k == static_cast<int>(x.size()) ? 1.0 : 2.0) * std::abs(acc) / n;
}

// Every order 0..128 present with its own amplitude 1 + k/100 and phase; what each signal keeps
// is read line by line with the naive DFT. kLineTol: FFT round-off over 256 points (1e-12) with
// margin.
TEST(TsaOrders, RegularResidualAndDifferenceKeepExactlyTheirOrders) {
  const int n = 256;
  std::vector<double> x(n, 0.0);
  for (int k = 0; k <= n / 2; ++k) {
    const double phase = 2 * k == n ? 0.0 : 0.1 * k;  // the Nyquist line has no phase to show
    for (int j = 0; j < n; ++j) x[j] += (1 + k / 100.0) * std::cos(2 * kPi * k * j / n + phase);
  }
  const std::vector<int> mesh{27, 40};
  // Hand-listed regular lines with one sideband: order 0, shaft order 1, 27 h +- {0,1} for
  // h = 1..4 (108 <= 128 < 135) and 40 h +- {0,1} for h = 1..3 (120 <= 128 < 160).
  const std::set<int> regular1{0,   1,   26, 27, 28, 53, 54, 55, 80,  81,  82, 107,
                               108, 109, 39, 40, 41, 79, 80, 81, 119, 120, 121};
  // Without sidebands.
  const std::set<int> regular0{0, 1, 27, 54, 81, 108, 40, 80, 120};
  constexpr double kLineTol = 1e-10;
  auto expect_lines = [&](const std::vector<double>& y, const std::set<int>& present,
                          const char* what) {
    for (int k = 0; k <= n / 2; ++k) {
      const double want = present.count(k) ? 1 + k / 100.0 : 0.0;
      EXPECT_NEAR(naive_amplitude(y, k), want, kLineTol) << what << " order " << k;
    }
  };
  std::set<int> all;
  for (int k = 0; k <= n / 2; ++k) all.insert(k);
  auto complement = [&](const std::set<int>& s) {
    std::set<int> c;
    for (int k : all)
      if (!s.count(k)) c.insert(k);
    return c;
  };
  expect_lines(detect::tsa_regular(x, mesh, 0), regular0, "regular(0)");
  expect_lines(detect::tsa_regular(x, mesh, 1), regular1, "regular(1)");
  expect_lines(detect::tsa_residual(x, mesh, 0), complement(regular0), "residual(0)");
  expect_lines(detect::tsa_residual(x, mesh, 1), complement(regular1), "residual(1)");
  expect_lines(detect::tsa_difference(x, mesh, 0), complement(regular1), "difference(0)");

  // Two more sidebands for the difference: +-3 around every mesh harmonic.
  std::set<int> regular3{0, 1};
  for (int z : mesh) {
    for (int c = z; c <= n / 2; c += z) {
      for (int j = -3; j <= 3; ++j) {
        if (c + j >= 1 && c + j <= n / 2) regular3.insert(c + j);
      }
    }
  }
  expect_lines(detect::tsa_difference(x, mesh, 2), complement(regular3), "difference(2)");

  // MATLAB's NumHarmonics = 2: shaft orders 1, 2 and mesh harmonics 1, 2 only.
  detect::TsaOrderOptions h2;
  h2.shaft_orders = 2;
  h2.mesh_harmonics = 2;
  expect_lines(detect::tsa_regular(x, mesh, 0, h2), {0, 1, 2, 27, 54, 40, 80}, "regular(H=2)");

  // regular(s) + residual(s) = TSA, sample by sample.
  const auto reg = detect::tsa_regular(x, mesh, 1);
  const auto res = detect::tsa_residual(x, mesh, 1);
  for (int j = 0; j < n; ++j) EXPECT_NEAR(reg[j] + res[j], x[j], 1e-10);
}

double kurtosis(const std::vector<double>& x) {
  double m = 0;
  for (double v : x) m += v;
  m /= static_cast<double>(x.size());
  double m2 = 0, m4 = 0;
  for (double v : x) {
    const double d = v - m;
    m2 += d * d;
    m4 += d * d * d * d;
  }
  m2 /= static_cast<double>(x.size());
  m4 /= static_cast<double>(x.size());
  return m4 / (m2 * m2);
}

// A gear of 27 teeth: shaft order 1 (runout), mesh harmonics 27, 54, 81, first-order sidebands
// of the mesh (amplitude modulation by the runout), and a localized impulse from one damaged
// tooth (a Gaussian of a quarter tooth's width at 0.3 rev). The difference signal holds none of
// the mesh lines and their first sidebands (naive DFT, 1e-10), while the impulse survives: its
// peak lies within half a tooth of 0.3 rev, and the kurtosis (FM4, Stewart 1977) that does not
// see the impulse under the mesh in the TSA (3.0; < 3.5 checked) is far above a Gaussian's 3 in
// the difference signal (34; > 10 checked).
TEST(TsaOrders, LocalizedImpulseSurvivesIntoTheDifferenceSignalWhileTheMeshDoesNot) {
  const int n = 1024, z = 27;
  const double theta0 = 0.3, width = 0.25 / z;
  std::vector<double> x(n);
  for (int j = 0; j < n; ++j) {
    const double th = static_cast<double>(j) / n;
    const double am = 1 + 0.2 * std::cos(2 * kPi * th);  // sidebands at 27 +- 1, ...
    double d = th - theta0;
    d -= std::round(d);
    x[j] = 0.3 * std::cos(2 * kPi * th) +
           am * (std::cos(2 * kPi * z * th) + 0.5 * std::cos(2 * kPi * 2 * z * th + 0.4) +
                 0.25 * std::cos(2 * kPi * 3 * z * th + 1.0)) +
           0.5 * std::exp(-0.5 * d * d / (width * width));
  }
  const std::vector<int> mesh{z};
  const auto diff = detect::tsa_difference(x, mesh);
  for (int h = 1; z * h <= n / 2; ++h) {
    for (int k : {z * h - 1, z * h, z * h + 1}) EXPECT_NEAR(naive_amplitude(diff, k), 0.0, 1e-10);
  }
  EXPECT_NEAR(naive_amplitude(diff, 1), 0.0, 1e-10);
  const auto peak = std::max_element(diff.begin(), diff.end()) - diff.begin();
  EXPECT_NEAR(static_cast<double>(peak) / n, theta0, 0.5 / z);
  EXPECT_LT(kurtosis(x), 3.5);
  EXPECT_GT(kurtosis(diff), 10.0);
}

TEST(TsaOrders, MeshOrderAboveTheNyquistOrderIsAnErrorNamingTheField) {
  const std::vector<double> x(64, 0.0);
  const std::vector<int> mesh{40};
  try {
    detect::tsa_regular(x, mesh);
    ADD_FAILURE() << "accepted";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mesh_orders"), std::string::npos) << e.what();
  }
  const std::vector<int> ok{8};
  EXPECT_THROW(detect::tsa_residual(x, ok, -1), diag::InputError);
  EXPECT_THROW(detect::tsa_difference(x, ok, -1), diag::InputError);
}

}  // namespace
