#include "detect/attribution/period_matcher.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <set>
#include <sstream>

#include "diag/error.hpp"
#include "diag/units.hpp"

namespace detect {

using diag::InputError;
using diag::units::kTwoPi;

namespace {

// The smooth part of the irregularity that turns with one shaft: a table over one revolution of
// the shaft, fitted by weighted least squares to a few Fourier orders of the bin means.
struct ShaftComponent {
  double period_rad = 0;      // shaft period in input angle
  int bins = 0;               // power of two
  std::vector<int> orders;    // Fourier orders kept (cycles per shaft revolution)
  std::vector<double> table;  // value at bin j (phase j / bins)

  double phase_pos(double x) const {
    const double p = x / period_rad;
    return (p - std::floor(p)) * bins;
  }
  double eval(double x) const {
    const double pos = phase_pos(x);
    int j = static_cast<int>(pos);
    const double t = pos - j;
    j &= bins - 1;
    return table[j] * (1.0 - t) + table[(j + 1) & (bins - 1)] * t;
  }
  void fit(const std::vector<double>& sum, const std::vector<double>& count) {
    // Columns: DC, then cos/sin of each order, evaluated at the bin centres.
    const int k = 1 + 2 * static_cast<int>(orders.size());
    Eigen::MatrixXd ata = Eigen::MatrixXd::Zero(k, k);
    Eigen::VectorXd atb = Eigen::VectorXd::Zero(k);
    Eigen::VectorXd row(k);
    for (int j = 0; j < bins; ++j) {
      if (count[j] <= 0) continue;
      const double ph = kTwoPi * j / bins;
      row(0) = 1.0;
      for (std::size_t o = 0; o < orders.size(); ++o) {
        row(1 + 2 * o) = std::cos(orders[o] * ph);
        row(2 + 2 * o) = std::sin(orders[o] * ph);
      }
      const double mean = sum[j] / count[j];
      ata.noalias() += count[j] * row * row.transpose();
      atb.noalias() += count[j] * mean * row;
    }
    // Ridge of 1e-9 of the trace keeps empty-bin cases solvable without biasing a full fit.
    ata.diagonal().array() += 1e-9 * (ata.trace() + 1.0);
    const Eigen::VectorXd c = ata.ldlt().solve(atb);
    table.assign(bins, 0.0);
    for (int j = 0; j < bins; ++j) {
      const double ph = kTwoPi * j / bins;
      double v = c(0);
      for (std::size_t o = 0; o < orders.size(); ++o) {
        v += c(1 + 2 * o) * std::cos(orders[o] * ph) + c(2 + 2 * o) * std::sin(orders[o] * ph);
      }
      table[j] = v;
    }
  }
};

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + v.size() / 2;
  std::nth_element(v.begin(), mid, v.end());
  double m = *mid;
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), mid));
  return m;
}

// 1.4826 MAD of e, on at most ~200k evenly strided samples.
double robust_sigma(const std::vector<double>& e) {
  const std::size_t stride = std::max<std::size_t>(1, e.size() / 200000);
  std::vector<double> s;
  s.reserve(e.size() / stride + 1);
  for (std::size_t i = 0; i < e.size(); i += stride) s.push_back(e[i]);
  const double med = median_of(s);
  for (double& v : s) v = std::abs(v - med);
  return 1.4826 * median_of(s);
}

struct Event {
  double onset = 0;   // input angle from the record's start [rad]
  double height = 0;  // [rad at the output]
  double start = 0;   // input angle where the run rose above half the threshold [rad]
  double end = 0;     // input angle where it fell below it again [rad]
};

// Runs of e above thr/2 that reach thr. Also marks them (dilated by their own length) in mask.
std::vector<Event> find_events(const std::vector<double>& x, const std::vector<double>& e,
                               double thr, std::vector<char>* mask) {
  std::vector<Event> events;
  const std::size_t n = e.size();
  if (mask) std::fill(mask->begin(), mask->end(), 0);
  std::size_t i = 0;
  while (i < n) {
    if (e[i] <= 0.5 * thr) {
      ++i;
      continue;
    }
    const std::size_t start = i;
    std::size_t pk = i;
    while (i < n && e[i] > 0.5 * thr) {
      if (e[i] > e[pk]) pk = i;
      ++i;
    }
    const std::size_t end = i;  // one past
    if (e[pk] < thr) continue;
    const double h = e[pk];
    // Onset: the rise is linear (the driven side stands still), so it starts as far before the
    // half-height crossing as the peak is after it.
    std::size_t k = start;
    while (k < pk && e[k] < 0.5 * h) ++k;
    double x_half = x[k];
    if (k > 0 && e[k] > e[k - 1]) {
      const double t = (0.5 * h - e[k - 1]) / (e[k] - e[k - 1]);
      x_half = x[k - 1] + std::clamp(t, 0.0, 1.0) * (x[k] - x[k - 1]);
    }
    events.push_back({std::max(0.0, 2.0 * x_half - x[pk]), h, x[start], x[end - 1]});
    if (mask) {
      const std::size_t len = end - start;
      const std::size_t a = start > len ? start - len : 0;
      const std::size_t b = std::min(n, end + len);
      std::fill(mask->begin() + a, mask->begin() + b, 1);
    }
  }
  return events;
}

struct Train {
  double period_rad = 0;
  std::vector<std::pair<int, int>> hits;  // (recurrence index, event index)
  int expected = 0;
  double measured_period_rad = 0;
  double phase_rad = 0;  // anchor: recurrence k is expected at phase_rad + k period_rad
  double first_onset = 0;
  std::vector<int> size_events;  // events that size the defect; empty: all hits
  int coincident = 0;            // hits that coincide with another train's recurrence
  std::string note;              // why the reading may be ambiguous
  bool ambiguous = false;        // another decomposition explains the same events
};

}  // namespace

void AttributionOptions::validate() const {
  diag::require(threshold_sigma >= 3 && std::isfinite(threshold_sigma), "attribution",
                "threshold_sigma", "must be >= 3");
  diag::require(min_event_rad >= 0, "attribution", "min_event_rad", "must be >= 0");
  diag::require(position_tolerance_rad >= 0, "attribution", "position_tolerance_rad",
                "must be >= 0");
  diag::require(period_tolerance > 0 && period_tolerance <= 0.2, "attribution", "period_tolerance",
                "must be in (0, 0.2]");
  diag::require(min_coverage > 0 && min_coverage <= 1, "attribution", "min_coverage",
                "must be in (0, 1]");
  diag::require(smooth_harmonics >= 0 && smooth_harmonics <= 64, "attribution", "smooth_harmonics",
                "must be in [0, 64]");
  diag::require(mesh_harmonics >= 0 && mesh_harmonics <= 8, "attribution", "mesh_harmonics",
                "must be in [0, 8]");
  diag::require(min_recurrences >= 2, "attribution", "min_recurrences", "must be >= 2");
}

// The output's lag behind its theoretical angle (x: the input angle from its first sample) with
// the path shafts' smooth periodic part (their low orders and mesh harmonics, backfitted) removed,
// fitted twice: the second time with the events found in the first residual masked out. sigma is
// the residual's robust noise, thr the event threshold.
struct LagResidual {
  std::vector<double> x, e;
  double sigma = 0, thr = 0;
};

LagResidual lag_residual(std::span<const double> in, std::span<const double> out,
                         const diag::Gearbox& gb, const std::vector<diag::PathStep>& path,
                         const std::vector<int>& path_shafts, const AttributionOptions& opt) {
  const std::size_t n = in.size();
  const double u = gb.total_ratio();
  const double span_out = out[n - 1] - out[0];
  // 1. The lag of the output behind its theoretical angle.
  const double sign = span_out < 0 ? -1.0 : 1.0;
  std::vector<double> x(n), e(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = in[i] - in[0];
  auto lag = [&](std::size_t i) { return x[i] / u - sign * (out[i] - out[0]); };

  // 2. Smooth periodic part, by backfitting over the path shafts.
  std::vector<ShaftComponent> comps;
  for (int s : path_shafts) {
    ShaftComponent c;
    c.period_rad = kTwoPi * gb.shaft_period_input_rev(s);
    std::set<int> orders;
    for (int h = 1; h <= opt.smooth_harmonics; ++h) orders.insert(h);
    for (const auto& st : path) {
      for (int g : {st.up_gear, st.down_gear}) {
        if (gb.shaft_of_gear(g) != s) continue;
        for (int k = 1; k <= opt.mesh_harmonics; ++k) orders.insert(k * gb.gears()[g].spec.teeth);
      }
    }
    c.orders.assign(orders.begin(), orders.end());
    const int max_order = c.orders.empty() ? 1 : c.orders.back();
    c.bins = 256;
    while (c.bins < 4 * max_order) c.bins *= 2;
    c.table.assign(c.bins, 0.0);
    comps.push_back(std::move(c));
  }
  // The smooth part has low orders only, so it is fitted on an evenly strided subsample of at
  // most ~5e5 points (hundreds per bin); the residual and the events use every sample.
  const std::size_t stride = std::max<std::size_t>(1, n / 250'000);
  std::vector<double> xs, rs, es;
  for (std::size_t i = 0; i < n; i += stride) {
    xs.push_back(x[i]);
    rs.push_back(lag(i));
  }
  std::vector<char> mask_s(xs.size(), 0), mask(n, 0);
  std::vector<double> sum, count;
  auto fit_smooth = [&] {
    es = rs;
    for (auto& c : comps) c.table.assign(c.bins, 0.0);
    constexpr int kBackfit = 3;  // sweeps over the shafts
    for (int sweep = 0; sweep < kBackfit; ++sweep) {
      for (auto& c : comps) {
        sum.assign(c.bins, 0.0);
        count.assign(c.bins, 0.0);
        for (std::size_t i = 0; i < xs.size(); ++i) {
          es[i] += c.eval(xs[i]);
          if (mask_s[i]) continue;
          const int j = static_cast<int>(c.phase_pos(xs[i]) + 0.5) & (c.bins - 1);
          sum[j] += es[i];
          count[j] += 1.0;
        }
        c.fit(sum, count);
        for (std::size_t i = 0; i < xs.size(); ++i) es[i] -= c.eval(xs[i]);
      }
    }
  };
  auto full_residual = [&] {
    for (std::size_t i = 0; i < n; ++i) {
      double v = lag(i);
      for (const auto& c : comps) v -= c.eval(x[i]);
      e[i] = v;
    }
  };
  double sigma = 0, thr = 0;
  // Fit, find the events, refit with them masked out, and find them again.
  fit_smooth();
  full_residual();
  sigma = robust_sigma(e);
  thr = std::max(opt.threshold_sigma * sigma, opt.min_event_rad);
  find_events(x, e, thr, &mask);
  for (std::size_t i = 0, k = 0; i < n; i += stride, ++k) mask_s[k] = mask[i];
  fit_smooth();
  full_residual();
  sigma = robust_sigma(e);
  thr = std::max(opt.threshold_sigma * sigma, opt.min_event_rad);

  return {std::move(x), std::move(e), sigma, thr};
}

// The angle records: the same length, at least 16 finite samples, the input angle increasing and
// turning, the output turning at the description's overall ratio (within 2 %).
void check_angles(std::span<const double> in, std::span<const double> out,
                  const diag::Gearbox& gb) {
  diag::require(in.size() == out.size(), "attribution", "output_angle_rad",
                "has " + std::to_string(out.size()) + " samples but input_angle_rad has " +
                    std::to_string(in.size()));
  diag::require(in.size() >= 16, "attribution", "input_angle_rad", "needs at least 16 samples");
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (!std::isfinite(in[i]) || !std::isfinite(out[i])) {
      diag::require(false, "attribution",
                    std::isfinite(in[i]) ? "output_angle_rad" : "input_angle_rad",
                    "sample " + std::to_string(i) + " is NaN or Inf");
    }
    if (i > 0 && in[i] < in[i - 1]) {
      diag::require(false, "attribution", "input_angle_rad",
                    "angles not increasing: sample " + std::to_string(i) + " (" +
                        std::to_string(in[i]) + ") is below sample " + std::to_string(i - 1) +
                        " (" + std::to_string(in[i - 1]) + ")");
    }
  }
  const std::size_t n = in.size();
  const double span_in = in[n - 1] - in[0];
  const double span_out = out[n - 1] - out[0];
  diag::require(span_in > 0, "attribution", "input_angle_rad", "the input shaft does not turn");
  const double u = gb.total_ratio();
  const double seen_ratio = span_in / std::abs(span_out);
  diag::require(std::abs(span_out) > 0 && std::abs(seen_ratio / u - 1.0) < 0.02, "attribution",
                "output_angle_rad",
                "the recording turns the output " + std::to_string(seen_ratio) +
                    " times slower than the input, but the gearbox's overall ratio is " +
                    std::to_string(u) + ": wrong gearbox description or channels");
}

namespace {

// A train accepted: the defect it stands for, on these shafts (several: equal periods).
struct Accepted {
  Train train;
  std::vector<int> shafts;
  double pulse_width = 0;  // median width of its events [rad of input]
};

// Step 4 of the matching: the events grouped into trains of the path shafts' periods, and the
// overlaps of two trains explained (4b). Holds the events and the trains accepted so far.
class TrainMatcher {
 public:
  TrainMatcher(const std::vector<Event>& events, double tau, double x_end)
      : events_(events),
        onsets_(events.size()),
        assigned_(events.size(), 0),
        tau_(tau),
        x_end_(x_end) {
    for (std::size_t k = 0; k < events.size(); ++k) onsets_[k] = events[k].onset;
  }

  // 4. For each candidate period, shortest first, the unassigned events clustered by phase; each
  // cluster whose train recurs often enough at the period is accepted (split_alternating first).
  void match(const std::map<double, std::vector<int>>& period_shafts, const diag::Gearbox& gb,
             double sigma, const AttributionOptions& opt);
  // 4b. Coincidences. Where another train passes during an event, the event is the overlap of
  // two defects (the output stays stopped while either gap is taken up, and the hold of one
  // delays the other's onset): its height and onset belong to neither defect alone. Such hits
  // are left out of a train's size and period fit when it has at least two others, and an event
  // no train claimed but during which a train passes is explained by the trains passing there
  // (a pulse split by the overlap) instead of being called unexplained.
  void resolve_coincidences();

  const std::vector<Accepted>& accepted() const { return accepted_; }
  bool assigned(std::size_t event) const { return assigned_[event] != 0; }

 private:
  static constexpr std::size_t kNoTrain = static_cast<std::size_t>(-1);

  // The event whose onset is nearest `pos` within the position tolerance; -1 when none.
  int nearest_event(double pos) const;
  void accept(const Train& t, const std::vector<int>& shafts);
  // The accepted trains other than `self` that pass during [lo, hi] of input angle: an expected
  // onset q whose pulse [q, q + width] meets it, within the position tolerance.
  std::vector<std::size_t> trains_passing(std::size_t self, double lo, double hi) const;
  // The train of period p anchored at phase phi: every recurrence within the record. A
  // recurrence without an event where an accepted train passes is not expected to show: the
  // other defect's pulse hides it (the output stays stopped while either gap is taken up).
  Train build_train(double p, double phi) const;
  // The least-squares period of the train's hits, and its first onset.
  void fit_period(Train& t) const;
  // Alternating heights: some recurrences of `t` carry a second defect on a slower shaft whose
  // period is a whole multiple m of this one, passing at the same time (seed 003, Fig. 9).
  // Explained as `t` (sized from its lower recurrences) plus a train of period m p for each
  // higher group, accepted here. Two defects on the slower shaft exactly p apart would give the
  // same events; that reading is named in the note and both confidences are halved.
  void split_alternating(Train& t, std::map<double, std::vector<int>>::const_iterator it,
                         const std::map<double, std::vector<int>>& period_shafts,
                         const diag::Gearbox& gb, double sigma);

  const std::vector<Event>& events_;
  std::vector<double> onsets_;
  std::vector<char> assigned_;
  std::vector<Accepted> accepted_;
  double tau_, x_end_;
};

int TrainMatcher::nearest_event(double pos) const {
  auto it = std::lower_bound(onsets_.begin(), onsets_.end(), pos - tau_);
  int best = -1;
  double best_d = tau_;
  for (; it != onsets_.end() && *it <= pos + tau_; ++it) {
    const double d = std::abs(*it - pos);
    if (d <= best_d) {
      best_d = d;
      best = static_cast<int>(it - onsets_.begin());
    }
  }
  return best;
}

void TrainMatcher::accept(const Train& t, const std::vector<int>& shafts) {
  std::vector<double> w;
  for (auto [k, ev] : t.hits) w.push_back(events_[ev].end - events_[ev].start);
  accepted_.push_back({t, shafts, median_of(w)});
}

std::vector<std::size_t> TrainMatcher::trains_passing(std::size_t self, double lo,
                                                      double hi) const {
  std::vector<std::size_t> out;
  for (std::size_t b = 0; b < accepted_.size(); ++b) {
    if (b == self) continue;
    const Train& t = accepted_[b].train;
    const double from = lo - tau_ - accepted_[b].pulse_width;
    const double q = t.phase_rad + std::ceil((from - t.phase_rad) / t.period_rad) * t.period_rad;
    if (q <= hi + tau_) out.push_back(b);
  }
  return out;
}

Train TrainMatcher::build_train(double p, double phi) const {
  Train t;
  t.period_rad = p;
  t.phase_rad = phi;
  for (long k = static_cast<long>(std::floor(-phi / p)); phi + k * p <= x_end_; ++k) {
    const double pos = phi + k * p;
    if (pos < -tau_) continue;
    const bool interior = pos >= 0 && pos <= x_end_ - 2 * tau_;
    const int ev = nearest_event(pos);
    if (interior && (ev >= 0 || trains_passing(kNoTrain, pos, pos).empty())) ++t.expected;
    if (ev >= 0) t.hits.emplace_back(static_cast<int>(k), ev);
  }
  return t;
}

void TrainMatcher::fit_period(Train& t) const {
  double sn = 0, sx = 0, snn = 0, snx = 0;
  for (auto [k, ev] : t.hits) {
    sn += k;
    sx += onsets_[ev];
    snn += double(k) * k;
    snx += k * onsets_[ev];
  }
  const double m = static_cast<double>(t.hits.size());
  const double den = m * snn - sn * sn;
  t.measured_period_rad = den > 0 ? (m * snx - sn * sx) / den : t.period_rad;
  t.first_onset = onsets_[t.hits.front().second];
}

void TrainMatcher::match(const std::map<double, std::vector<int>>& period_shafts,
                         const diag::Gearbox& gb, double sigma, const AttributionOptions& opt) {
  for (auto it = period_shafts.begin(); it != period_shafts.end(); ++it) {
    const double p = it->first;
    // Cluster the unassigned events by phase modulo p.
    std::vector<std::pair<double, int>> phases;
    for (std::size_t k = 0; k < events_.size(); ++k) {
      if (!assigned_[k]) phases.emplace_back(std::fmod(onsets_[k], p), static_cast<int>(k));
    }
    std::sort(phases.begin(), phases.end());
    std::vector<std::vector<std::pair<double, int>>> clusters;
    for (const auto& ph : phases) {
      if (clusters.empty() || ph.first - clusters.back().back().first > tau_)
        clusters.emplace_back();
      clusters.back().push_back(ph);
    }
    if (clusters.size() > 1 &&
        clusters.front().front().first + p - clusters.back().back().first <= tau_) {
      for (auto& ph : clusters.back()) ph.first -= p;  // wrap-around: one cluster
      clusters.front().insert(clusters.front().begin(), clusters.back().begin(),
                              clusters.back().end());
      clusters.pop_back();
    }
    for (const auto& cl : clusters) {
      if (assigned_[cl.front().second] && cl.size() == 1) continue;
      std::vector<double> ph;
      for (const auto& c : cl) ph.push_back(c.first);
      Train t = build_train(p, median_of(ph));
      const int hits_interior = static_cast<int>(t.hits.size());
      if (t.expected < 3 || hits_interior < 3 || hits_interior < opt.min_coverage * t.expected) {
        continue;
      }
      fit_period(t);
      if (std::abs(t.measured_period_rad - p) > opt.period_tolerance * p) continue;
      split_alternating(t, it, period_shafts, gb, sigma);
      for (auto [k, ev] : t.hits) assigned_[ev] = 1;
      accept(t, it->second);
    }
  }
}

void TrainMatcher::split_alternating(Train& t,
                                     std::map<double, std::vector<int>>::const_iterator it,
                                     const std::map<double, std::vector<int>>& period_shafts,
                                     const diag::Gearbox& gb, double sigma) {
  const double p = it->first;
  for (auto jt = std::next(it); jt != period_shafts.end(); ++jt) {
    const double ratio = jt->first / p;
    const long m = std::lround(ratio);
    if (m < 2 || std::abs(ratio - m) > 1e-6 * ratio) continue;
    std::vector<std::vector<int>> groups(m);
    for (auto [k, ev] : t.hits) groups[((k % m) + m) % m].push_back(ev);
    std::vector<double> med(m, 0.0);
    bool all_seen = true;
    for (long r = 0; r < m; ++r) {
      std::vector<double> h;
      for (int ev : groups[r]) h.push_back(events_[ev].height);
      all_seen &= h.size() >= 2;
      med[r] = median_of(h);
    }
    if (!all_seen) continue;
    const double low = *std::min_element(med.begin(), med.end());
    const double split = std::max(6.0 * sigma, 0.15 * low);
    std::vector<Train> slow;
    for (long r = 0; r < m; ++r) {
      if (med[r] - low <= split) continue;
      std::vector<double> anchors;
      for (int ev : groups[r]) anchors.push_back(std::fmod(onsets_[ev], jt->first));
      Train sub = build_train(jt->first, median_of(anchors));
      if (sub.hits.size() < 2) continue;
      fit_period(sub);
      slow.push_back(sub);
    }
    if (slow.empty()) continue;
    t.size_events.clear();
    for (long r = 0; r < m; ++r) {
      if (med[r] - low <= split)
        t.size_events.insert(t.size_events.end(), groups[r].begin(), groups[r].end());
    }
    std::ostringstream alt_text;
    alt_text << "one recurrence in " << m << " coincides with a defect on shaft '"
             << gb.shafts()[jt->second.front()].name << "' (period " << jt->first / kTwoPi
             << " input rev); " << m << " defects on that shaft, " << p / kTwoPi
             << " input rev apart, would give the same events";
    const std::string alt = alt_text.str();
    t.note = alt;
    t.ambiguous = true;
    for (auto& sub : slow) {
      sub.note = alt;
      sub.ambiguous = true;
      for (auto [k, ev] : sub.hits) assigned_[ev] = 1;
      accept(sub, jt->second);
    }
    return;
  }
}

void TrainMatcher::resolve_coincidences() {
  for (std::size_t a = 0; a < accepted_.size(); ++a) {
    Train& t = accepted_[a].train;
    Train clean = t;
    clean.hits.clear();
    for (auto [k, ev] : t.hits) {
      if (trains_passing(a, events_[ev].start, events_[ev].end).empty()) {
        clean.hits.emplace_back(k, ev);
      }
    }
    if (clean.hits.size() == t.hits.size() || clean.hits.size() < 2) continue;
    t.coincident = static_cast<int>(t.hits.size() - clean.hits.size());
    fit_period(clean);
    t.measured_period_rad = clean.measured_period_rad;
    t.first_onset = clean.first_onset -
                    (clean.hits.front().first - t.hits.front().first) * t.measured_period_rad;
    std::vector<int> sizing;
    for (auto [k, ev] : clean.hits) {
      if (t.size_events.empty() ||
          std::find(t.size_events.begin(), t.size_events.end(), ev) != t.size_events.end()) {
        sizing.push_back(ev);
      }
    }
    if (sizing.size() >= 2) t.size_events = sizing;
  }
  for (std::size_t k = 0; k < events_.size(); ++k) {
    if (assigned_[k]) continue;
    const auto passing = trains_passing(kNoTrain, events_[k].start, events_[k].end);
    if (passing.empty()) continue;
    assigned_[k] = 1;
    for (std::size_t b : passing) ++accepted_[b].train.coincident;
  }
}

// 5. The finding of an accepted train: its shaft(s) and their gears on the power path, its size
// on the gear (the median height of its sizing events, scaled from the output to the shaft), and
// a confidence from its coverage, period match and the spread of its heights.
Finding train_finding(const Accepted& a, const std::vector<Event>& events, const diag::Gearbox& gb,
                      const AttributionOptions& opt) {
  Finding f;
  std::vector<std::string> shaft_names;
  for (int s : a.shafts) {
    shaft_names.push_back(gb.shafts()[s].name);
    for (int g : gb.shafts()[s].gears) {
      if (gb.on_power_path(g)) f.gears.push_back(gb.gears()[g].name);
    }
  }
  f.shaft = shaft_names.front();
  for (std::size_t k = 1; k < shaft_names.size(); ++k) f.shaft += " or " + shaft_names[k];
  std::vector<double> heights;
  if (a.train.size_events.empty()) {
    for (auto [k, ev] : a.train.hits) heights.push_back(events[ev].height);
  } else {
    for (int ev : a.train.size_events) heights.push_back(events[ev].height);
  }
  f.kind = "attribution";
  f.fault = diag::FaultKind::kToothDamage;
  f.note = a.train.note;
  const double size_output_rad = median_of(heights);
  f.size = size_output_rad * std::abs(gb.shafts()[a.shafts.front()].speed_ratio /
                                      gb.shafts()[gb.output_shaft()].speed_ratio);
  f.size_unit = "rad";
  const int seen = static_cast<int>(a.train.hits.size());
  f.evidence = {{"period_input_rev", a.train.period_rad / kTwoPi},
                {"measured_period_input_rev", a.train.measured_period_rad / kTwoPi},
                {"size_output_rad", size_output_rad},
                {"size_gear_rad", f.size},
                {"first_event_input_rad", a.train.first_onset},
                {"events", seen},
                {"expected_events", std::max(a.train.expected, seen)},
                {"coincident_events", a.train.coincident}};
  std::vector<double> dev;
  for (double h : heights) dev.push_back(std::abs(h - size_output_rad));
  const double cv = size_output_rad > 0 ? 1.4826 * median_of(dev) / size_output_rad : 1.0;
  const double coverage = std::min(1.0, double(seen) / std::max(1, a.train.expected));
  const double period_match =
      std::max(0.0, 1.0 - std::abs(a.train.measured_period_rad - a.train.period_rad) /
                              (opt.period_tolerance * a.train.period_rad));
  f.confidence = std::clamp(coverage * period_match / (1.0 + cv), 0.0, 1.0);
  if (a.train.ambiguous) f.confidence *= 0.5;
  return f;
}

// The distinct path-shaft periods [rad of input], shortest first, each with its shafts.
std::map<double, std::vector<int>> candidate_periods(const diag::Gearbox& gb,
                                                     const std::vector<int>& path_shafts) {
  std::map<double, std::vector<int>> period_shafts;
  for (int s : path_shafts) {
    const double p = kTwoPi * gb.shaft_period_input_rev(s);
    bool placed = false;
    for (auto& [q, list] : period_shafts) {
      if (std::abs(q - p) <= 1e-9 * p) {
        if (std::find(list.begin(), list.end(), s) == list.end()) list.push_back(s);
        placed = true;
      }
    }
    if (!placed) period_shafts[p].push_back(s);
  }
  return period_shafts;
}

}  // namespace

AttributionResult attribute_defects(std::span<const double> in, std::span<const double> out,
                                    const diag::Gearbox& gb, const AttributionOptions& opt) {
  opt.validate();
  check_angles(in, out, gb);
  const std::size_t n = in.size();
  const double span_in = in[n - 1] - in[0];

  // Path shafts and their periods in input angle.
  const auto& path = gb.power_path();
  std::vector<int> path_shafts{gb.input_shaft()};
  for (const auto& st : path) path_shafts.push_back(gb.shaft_of_gear(st.down_gear));
  double longest_rev = 0;
  int longest_shaft = gb.input_shaft();
  for (int s : path_shafts) {
    if (gb.shaft_period_input_rev(s) > longest_rev) {
      longest_rev = gb.shaft_period_input_rev(s);
      longest_shaft = s;
    }
  }
  const double record_rev = span_in / kTwoPi;
  if (record_rev < opt.min_recurrences * longest_rev) {
    std::ostringstream m;
    m << "too short: the record covers " << record_rev << " input revolutions; at least "
      << opt.min_recurrences * longest_rev << " are needed (" << opt.min_recurrences
      << " recurrences of the longest period, " << longest_rev << " input revolutions of shaft '"
      << gb.shafts()[longest_shaft].name << "')";
    diag::require(false, "attribution", "input_angle_rad", m.str());
  }

  // 1-2. The lag of the output behind its theoretical angle, less the smooth periodic part.
  const double step = span_in / static_cast<double>(n - 1);
  const LagResidual lr = lag_residual(in, out, gb, path, path_shafts, opt);

  // 3. Events.
  std::vector<Event> events = find_events(lr.x, lr.e, lr.thr, nullptr);
  std::sort(events.begin(), events.end(),
            [](const Event& a, const Event& b) { return a.onset < b.onset; });

  AttributionResult res;
  res.events_detected = static_cast<int>(events.size());
  res.noise_rad = lr.sigma;
  res.threshold_rad = lr.thr;
  res.record_input_rev = record_rev;

  // 4. Trains of the path shafts' periods.
  const double tau = opt.position_tolerance_rad > 0
                         ? opt.position_tolerance_rad
                         : std::max(5.0 * step, diag::units::deg_to_rad(0.5));
  TrainMatcher matcher(events, tau, lr.x[n - 1]);
  matcher.match(candidate_periods(gb, path_shafts), gb, lr.sigma, opt);
  matcher.resolve_coincidences();

  // 5. Findings.
  for (const Accepted& a : matcher.accepted()) {
    res.findings.push_back(train_finding(a, events, gb, opt));
  }
  std::sort(res.findings.begin(), res.findings.end(), [](const Finding& a, const Finding& b) {
    return a.evidence_value("first_event_input_rad") < b.evidence_value("first_event_input_rad");
  });
  for (std::size_t k = 0; k < events.size(); ++k) {
    if (!matcher.assigned(k)) res.unexplained.push_back({events[k].onset, events[k].height});
  }
  res.multiplicity = !res.unexplained.empty();
  res.status = res.multiplicity       ? AttributionStatus::kMultiplicity
               : res.findings.empty() ? AttributionStatus::kHealthy
                                      : AttributionStatus::kAttributed;
  return res;
}

std::string_view to_string(AttributionStatus s) {
  switch (s) {
    case AttributionStatus::kHealthy:
      return "healthy";
    case AttributionStatus::kAttributed:
      return "attributed";
    case AttributionStatus::kMultiplicity:
      return "multiplicity";
  }
  return "unknown";
}

nlohmann::json to_json(const AttributionResult& r) {
  nlohmann::json j;
  j["status"] = std::string(to_string(r.status));
  j["findings"] = nlohmann::json::array();
  for (const auto& f : r.findings) {
    j["findings"].push_back(to_json(f));
  }
  j["multiplicity"] = r.multiplicity;
  j["unexplained"] = nlohmann::json::array();
  for (const auto& u : r.unexplained) {
    j["unexplained"].push_back(
        {{"input_angle_rad", u.input_angle_rad}, {"size_output_rad", u.size_output_rad}});
  }
  j["events_detected"] = r.events_detected;
  j["noise_rad"] = r.noise_rad;
  j["threshold_rad"] = r.threshold_rad;
  j["record_input_rev"] = r.record_input_rev;
  return j;
}

std::string format_table(const AttributionResult& r) {
  using diag::units::rad_to_deg;
  std::ostringstream o;
  o << std::fixed;
  o << "status: " << to_string(r.status) << "  (" << r.events_detected << " events over "
    << std::setprecision(1) << r.record_input_rev << " input rev; threshold "
    << std::setprecision(4) << rad_to_deg(r.threshold_rad) << " deg at the output)\n";
  if (r.findings.empty()) {
    o << "no defect found\n";
  } else {
    o << "  shaft        gears            period [in rev]  size@output [deg]  size@gear [deg]  "
         "first event [in deg]  seen/expected  confidence\n";
    for (const auto& f : r.findings) {
      std::string gears;
      for (const auto& g : f.gears) gears += (gears.empty() ? "" : ",") + g;
      const auto e = [&f](const char* name) { return f.evidence_value(name); };
      o << "  " << std::left << std::setw(13) << f.shaft << std::setw(17) << gears << std::right
        << std::setprecision(3) << std::setw(15) << e("period_input_rev") << std::setprecision(4)
        << std::setw(19) << rad_to_deg(e("size_output_rad")) << std::setw(17)
        << rad_to_deg(e("size_gear_rad")) << std::setprecision(2) << std::setw(22)
        << rad_to_deg(e("first_event_input_rad")) << std::setw(10) << int(e("events")) << "/"
        << std::left << std::setw(5) << int(e("expected_events")) << std::right
        << std::setprecision(2) << std::setw(10) << f.confidence << "\n";
      if (!f.note.empty()) o << "      note: " << f.note << "\n";
      if (e("coincident_events") > 0) {
        o << "      " << int(e("coincident_events"))
          << " event(s) coincide with another train's: not used for the size\n";
      }
    }
  }
  if (r.multiplicity) {
    o << "multiplicity: " << r.unexplained.size()
      << " event(s) match no recurrence period: several defects, not separable:\n";
    for (const auto& u : r.unexplained) {
      o << "  at input " << std::setprecision(2) << rad_to_deg(u.input_angle_rad) << " deg, size "
        << std::setprecision(4) << rad_to_deg(u.size_output_rad) << " deg at the output\n";
    }
  }
  return o.str();
}

}  // namespace detect
