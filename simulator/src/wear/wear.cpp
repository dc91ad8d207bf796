#include "sim/wear/wear.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include "diag/error.hpp"
#include "diag/geometry/profile.hpp"
#include "sim/mesh/mesh_stiffness.hpp"

namespace sim {

namespace {

constexpr double kPi = std::numbers::pi;

void require(bool ok, const char* field, const std::string& reason) {
  if (!ok) throw diag::InputError(diag::format_error("wear options", field, reason));
}

double interp(const std::vector<double>& x, const std::vector<double>& y, double xq) {
  if (xq <= x.front()) return y.front();
  if (xq >= x.back()) return y.back();
  const auto i = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), xq) - x.begin());
  const double t = (xq - x[i - 1]) / (x[i] - x[i - 1]);
  return y[i - 1] + t * (y[i] - y[i - 1]);
}

// Loads of the pairs with stiffnesses k and gaps g sharing the force F (header formula).
std::vector<double> share_load(const std::vector<double>& k, const std::vector<double>& g,
                               double F) {
  std::vector<std::size_t> order(k.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return g[a] < g[b]; });
  double ksum = 0, kgsum = 0, d = 0;
  for (std::size_t n = 0; n < order.size(); ++n) {
    const std::size_t i = order[n];
    if (!(k[i] > 0)) continue;
    ksum += k[i];
    kgsum += k[i] * g[i];
    d = (F + kgsum) / ksum;
    if (n + 1 == order.size() || d <= g[order[n + 1]]) break;
  }
  std::vector<double> f(k.size(), 0.0);
  for (std::size_t i = 0; i < k.size(); ++i) f[i] = std::max(0.0, k[i] * (d - g[i]));
  return f;
}

// Unloaded TE [rad, driven] of the pair with every tooth's flank worn by the given depths.
std::vector<double> worn_unloaded_te(const diag::GearPair& p, const diag::Flank& new1,
                                     const diag::Flank& new2, const std::vector<double>& roll1,
                                     const std::vector<double>& d1,
                                     const std::vector<double>& roll2,
                                     const std::vector<double>& d2,
                                     const std::vector<double>& phis) {
  const auto f1 = std::make_shared<const diag::Flank>(diag::apply_normal_depth(new1, roll1, d1));
  const auto f2 = std::make_shared<const diag::Flank>(diag::apply_normal_depth(new2, roll2, d2));
  const diag::MeshFlanks mf{
      std::vector<std::shared_ptr<const diag::Flank>>(p.driver().teeth(), f1),
      std::vector<std::shared_ptr<const diag::Flank>>(p.driven().teeth(), f2)};
  return diag::unloaded_transmission_error(p, mf, phis);
}

double peak_to_peak(const std::vector<double>& v) {
  return *std::max_element(v.begin(), v.end()) - *std::min_element(v.begin(), v.end());
}

}  // namespace

const char* wear_law_name(WearLaw law) { return law == WearLaw::kArchard ? "archard" : "seed004"; }

WearLaw parse_wear_law(const std::string& name, const std::string& field) {
  if (name == "archard") return WearLaw::kArchard;
  if (name == "seed004") return WearLaw::kSeed004;
  throw diag::InputError(
      diag::format_error(field, "", "must be archard or seed004 (got '" + name + "')"));
}

void WearOptions::validate() const {
  // 1e15 cycles is centuries of running at any gear speed; a bound keeps the run finite.
  require(cycles > 0 && cycles <= 1e15, "cycles", "must be in (0, 1e15]");
  require(steps >= 1 && steps <= 100000, "steps", "must be in [1, 100000]");
  require(profile_points >= 11 && profile_points <= 100000, "profile_points",
          "must be in [11, 100000]");
  require(archard_coefficient_m2_per_n > 0 && archard_coefficient_m2_per_n < 1e-6,
          "archard_coefficient", "must be in (0, 1e-6) m^2/N");
  require(std::isfinite(seed_exponent_m) && std::abs(seed_exponent_m) <= 5, "seed_exponent_m",
          "must be in [-5, 5]");
  require(seed_exponent_n >= 0 && seed_exponent_n <= 5, "seed_exponent_n", "must be in [0, 5]");
  require(seed_max_depth_per_cycle_m >= 0 && seed_max_depth_per_cycle_m < 1e-3,
          "seed_max_depth_per_cycle", "must be in [0, 1e-3) m");
  require(depth_limit_m > 0 && depth_limit_m < 0.01, "depth_limit", "must be in (0, 10) mm");
  // 1e7 N m is far above any gear set this models; past it the contact stresses overflow.
  require(std::isfinite(input_torque_nm) && input_torque_nm <= 1e7, "input_torque_nm",
          "must be finite and at most 1e7 N m");
  require(substep_depth_m >= 1e-8 && substep_depth_m <= 1e-3, "substep_depth",
          "must be in [0.01, 1000] um");
  require(te_points_per_mesh >= 16 && te_points_per_mesh <= 4096, "te_points_per_mesh",
          "must be in [16, 4096]");
}

double shape_correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = std::min(a.size(), b.size());
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < n; ++i) ma += a[i] / n, mb += b[i] / n;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

WearHistory simulate_wear(const diag::Gearbox& gb, int mesh, const WearOptions& o) {
  o.validate();
  if (mesh < 0 || mesh >= static_cast<int>(gb.meshes().size())) {
    throw diag::InputError(diag::format_error("wear", "mesh", "index out of range"));
  }
  const diag::Mesh& me = gb.meshes()[static_cast<std::size_t>(mesh)];
  const diag::GearPair& p = me.pair;
  const diag::Gear &g1 = p.driver(), &g2 = p.driven();
  const double rb1 = g1.base_radius_m(), rb2 = g2.base_radius_m(), L = p.loa_length_m();
  const double u = p.ratio(), pb = p.base_pitch_m();
  const double s0 = p.s_start_m(), s1 = p.s_end_m(), sp = p.s_pitch_m();
  // Load: the input torque carried to the driver's shaft (no losses).
  const double shaft_ratio =
      std::abs(gb.shafts()[static_cast<std::size_t>(gb.shaft_of_gear(me.driver))].speed_ratio);
  const double torque =
      (o.input_torque_nm >= 0 ? o.input_torque_nm : gb.input().torque_nm) / shaft_ratio;
  if (!(torque > 0)) {
    throw diag::InputError(
        diag::format_error("gearbox", "input.torque_nm", "must be > 0 for a wear history"));
  }
  const double F = torque / rb1;
  const double b = std::min(g1.spec().face_width_m, g2.spec().face_width_m);
  const double e_star = 2.0 * hertz_stiffness(p) / (kPi * b);
  const double omega1 = 2 * kPi * gb.shaft_speed_hz(gb.shaft_of_gear(me.driver));
  const MeshStiffness stiffness(p);

  // Profile grid on the path of contact with a node at the pitch point.
  WearHistory h;
  h.normal_force_n = F;
  std::vector<double> s;
  const int n_app =
      std::clamp(static_cast<int>(std::lround((o.profile_points - 1) * (sp - s0) / (s1 - s0))), 1,
                 o.profile_points - 2);
  for (int i = 0; i < n_app; ++i) s.push_back(s0 + (sp - s0) * i / n_app);
  const int n_rec = o.profile_points - 1 - n_app;
  for (int i = 0; i <= n_rec; ++i) s.push_back(sp + (s1 - sp) * i / n_rec);
  const std::size_t np = s.size();
  for (std::size_t i = 0; i < np; ++i) {
    h.roll_driver_m.push_back(s[i]);
    h.radius_driver_m.push_back(std::hypot(rb1, s[i]));
    h.pair_stiffness_n_per_m.push_back(stiffness.healthy_pair_stiffness(s[i]));
  }
  for (std::size_t i = np; i-- > 0;) {  // driven roll increasing: s decreasing
    h.roll_driven_m.push_back(L - s[i]);
    h.radius_driven_m.push_back(std::hypot(rb2, L - s[i]));
  }
  std::vector<double> d1(np, 0.0), d2(np, 0.0);  // depths on the driver / driven grids

  // The pairs in contact when one of them sits at x (x itself included), with their loads.
  struct Sharing {
    std::vector<double> pos, load;
  };
  auto sharing = [&](double x) {
    Sharing sh;
    const double first = x - pb * std::floor((x - s0) / pb + 1e-12);
    for (double q = first; q <= s1 + 1e-12; q += pb) sh.pos.push_back(q);
    std::vector<double> k, g;
    for (double q : sh.pos) {
      k.push_back(stiffness.healthy_pair_stiffness(std::clamp(q, s0, s1)));
      g.push_back(interp(h.roll_driver_m, d1, q) + interp(h.roll_driven_m, d2, L - q));
    }
    sh.load = share_load(k, g, F);
    return sh;
  };
  auto load_at = [&](double x) {
    const Sharing sh = sharing(x);
    for (std::size_t j = 0; j < sh.pos.size(); ++j) {
      if (std::abs(sh.pos[j] - x) < 1e-12) return sh.load[j];
    }
    return 0.0;
  };
  // Per-pass depth at the grid points (driver grid index i; the driven point is np-1-i). The
  // seed's intensity counts only where the flank is in contact under load (header, "Contact"):
  // seed_scale = U_max / I_max is fixed on the new pair, where every point is loaded.
  double seed_scale = 1.0;
  auto per_pass = [&](WearLaw law, std::vector<double>& w1, std::vector<double>& w2) {
    w1.assign(np, 0.0);
    w2.assign(np, 0.0);
    for (std::size_t i = 0; i < np; ++i) {
      const auto k = p.kinematics(s[i], omega1);
      const double lam1 = std::abs(k.specific_sliding_1), lam2 = std::abs(k.specific_sliding_2);
      const double load = load_at(s[i]);
      if (law == WearLaw::kArchard) {
        const double fw = load / b;
        w1[i] = o.archard_coefficient_m2_per_n * fw * lam1;
        w2[np - 1 - i] = o.archard_coefficient_m2_per_n * fw * lam2;
      } else if (load > 0) {
        const double common = seed_scale * std::pow(k.reduced_radius_m, o.seed_exponent_m) *
                              std::pow(std::abs(k.sliding_m_per_s), o.seed_exponent_n);
        w1[i] = lam1 * common;
        w2[np - 1 - i] = lam2 * common;
      }
    }
  };
  auto largest = [](const std::vector<double>& a, const std::vector<double>& b) {
    return std::max(*std::max_element(a.begin(), a.end()), *std::max_element(b.begin(), b.end()));
  };
  if (o.law == WearLaw::kSeed004) {
    std::vector<double> a1, a2;
    double umax = o.seed_max_depth_per_cycle_m;
    if (umax == 0) {
      per_pass(WearLaw::kArchard, a1, a2);
      umax = largest(a1, a2);
    }
    per_pass(WearLaw::kSeed004, a1, a2);
    const double imax = largest(a1, a2);
    seed_scale = imax > 0 ? umax / imax : 0.0;
  }

  // State measures: unloaded TE by rolling the worn flanks, loaded sharing over a mesh period.
  const diag::Flank new1 = diag::generate_tooth(g1).flank, new2 = diag::generate_tooth(g2).flank;
  const int nt = o.te_points_per_mesh;
  std::vector<double> phis;
  for (int i = 0; i < nt; ++i) phis.push_back(p.mesh_period_rad() * (i + 0.5) / nt);
  struct State {
    double te_pp, te_rolled_pp;
    std::array<double, 3> harm;
    double eps, k_mean, p_max;
  };
  auto measure = [&]() {
    State st{};
    WornPair w;
    w.roll_driver_m = h.roll_driver_m;
    w.roll_driven_m = h.roll_driven_m;
    w.depth_driver_m = d1;
    w.depth_driven_m = d2;
    const std::vector<double> te = worn_gap_transmission_error(p, w, nt);
    st.te_pp = peak_to_peak(te);
    st.te_rolled_pp = peak_to_peak(
        worn_unloaded_te(p, new1, new2, h.roll_driver_m, d1, h.roll_driven_m, d2, phis));
    for (int hmn = 1; hmn <= 3; ++hmn) {
      double re = 0, im = 0;
      for (int i = 0; i < nt; ++i) {
        re += te[i] * std::cos(2 * kPi * hmn * i / nt);
        im += te[i] * std::sin(2 * kPi * hmn * i / nt);
      }
      st.harm[hmn - 1] = 2.0 * std::hypot(re, im) / nt;
    }
    for (int i = 0; i < nt; ++i) {
      const Sharing sh = sharing(s0 + pb * (i + 0.5) / nt);
      for (std::size_t j = 0; j < sh.pos.size(); ++j) {
        if (!(sh.load[j] > 0)) continue;
        st.eps += 1.0 / nt;
        st.k_mean += stiffness.healthy_pair_stiffness(std::clamp(sh.pos[j], s0, s1)) / nt;
        const double rho1 = sh.pos[j], rho2 = L - sh.pos[j];
        const double R = rho1 * rho2 / (rho1 + rho2), fw = sh.load[j] / b;
        st.p_max = std::max(st.p_max, std::sqrt(fw * e_star / (kPi * R)));
      }
    }
    return st;
  };
  const State st0 = measure();
  h.te_peak_to_peak_new_rad = st0.te_pp;
  h.loaded_contact_ratio_new = st0.eps;
  h.max_pressure_new_pa = st0.p_max;

  const double block = o.cycles / o.steps;
  std::vector<double> w1, w2;
  for (int k = 0; k < o.steps; ++k) {
    // Sub-blocks (header, "Steps"): at most o.substep_depth_m of wear at any point between two
    // load sharings (both laws: the seed's depends on which points are in contact).
    // The depth limit is checked after every sub-block, not only per step: a step of very many
    // cycles (or a large load) then ends once the limit is reached instead of running on.
    bool at_limit = false;
    for (double left = block; left > 0 && !at_limit;) {
      per_pass(o.law, w1, w2);
      const double peak = std::max(*std::max_element(w1.begin(), w1.end()),
                                   *std::max_element(w2.begin(), w2.end()) / u);
      if (!std::isfinite(peak)) {
        throw diag::InputError(diag::format_error(
            "wear", "load", "the wear per cycle is not finite (is the torque far too large?)"));
      }
      double dc = left;
      if (peak * dc > o.substep_depth_m) {
        dc = o.substep_depth_m / peak;
        if (left - dc < 1e-9 * block) dc = left;
      }
      for (std::size_t i = 0; i < np; ++i) {
        d1[i] += dc * w1[i];
        d2[i] += dc / u * w2[i];
      }
      left = dc == left ? 0.0 : left - dc;
      at_limit = largest(d1, d2) >= o.depth_limit_m;
    }
    const State st = measure();
    h.cycles.push_back(block * (k + 1));
    h.depth_driver_m.push_back(d1);
    h.depth_driven_m.push_back(d2);
    h.te_peak_to_peak_rad.push_back(st.te_pp);
    h.te_harmonics_rad.push_back(st.harm);
    h.te_rolled_peak_to_peak_rad.push_back(st.te_rolled_pp);
    h.loaded_contact_ratio.push_back(st.eps);
    h.mesh_stiffness_n_per_m.push_back(st.k_mean);
    h.max_pressure_pa.push_back(st.p_max);
    if (largest(d1, d2) >= o.depth_limit_m) {
      h.stopped_at_limit = k + 1 < o.steps;
      break;
    }
  }
  return h;
}

double WornPair::max_depth_driver_m() const {
  return depth_driver_m.empty() ? 0.0
                                : *std::max_element(depth_driver_m.begin(), depth_driver_m.end());
}

double WornPair::max_depth_driven_m() const {
  return depth_driven_m.empty() ? 0.0
                                : *std::max_element(depth_driven_m.begin(), depth_driven_m.end());
}

WornPair worn_pair(const WearHistory& h, std::size_t step) {
  if (step >= h.cycles.size()) {
    throw diag::InputError(diag::format_error("wear history", "step", "out of range"));
  }
  WornPair w;
  w.cycles = h.cycles[step];
  w.roll_driver_m = h.roll_driver_m;
  w.roll_driven_m = h.roll_driven_m;
  w.depth_driver_m = h.depth_driver_m[step];
  w.depth_driven_m = h.depth_driven_m[step];
  w.te_peak_to_peak_rad = h.te_peak_to_peak_rad[step];
  return w;
}

WornPair wear_pair(const diag::Gearbox& gb, int mesh, WearOptions o, double target_depth_m) {
  if (!(target_depth_m >= 0) || !(target_depth_m < 0.01)) {
    throw diag::InputError(diag::format_error("wear", "target depth", "must be in [0, 10) mm"));
  }
  if (target_depth_m == 0) {
    const WearHistory h = simulate_wear(gb, mesh, o);
    return worn_pair(h, h.cycles.size() - 1);
  }
  // The new pair's rate sets the first length tried: one block of one revolution.
  WearOptions probe = o;
  probe.cycles = 1;
  probe.steps = 1;
  const WornPair one = worn_pair(simulate_wear(gb, mesh, probe), 0);
  const double rate = std::max(one.max_depth_driver_m(), one.max_depth_driven_m());
  o.depth_limit_m = target_depth_m;
  o.cycles = rate > 0 ? 2.0 * target_depth_m / rate : 1e6;
  for (; o.cycles <= 1e15; o.cycles *= 4) {
    const WearHistory h = simulate_wear(gb, mesh, o);
    const std::size_t k = h.cycles.size() - 1;
    WornPair hi = worn_pair(h, k);
    const double d_hi = std::max(hi.max_depth_driver_m(), hi.max_depth_driven_m());
    if (d_hi < target_depth_m) continue;
    WornPair lo;  // the state before: the previous step, or the new pair
    if (k > 0) {
      lo = worn_pair(h, k - 1);
    } else {
      lo = hi;
      lo.cycles = 0;
      std::fill(lo.depth_driver_m.begin(), lo.depth_driver_m.end(), 0.0);
      std::fill(lo.depth_driven_m.begin(), lo.depth_driven_m.end(), 0.0);
    }
    // The deepest point of the blend lo + t (hi - lo) grows with t (depths only grow); where it
    // equals the target is found by bisection (the deepest point may move between lo and hi).
    WornPair w = hi;
    auto blend = [&](double t) {
      w.cycles = lo.cycles + t * (hi.cycles - lo.cycles);
      for (std::size_t i = 0; i < w.depth_driver_m.size(); ++i) {
        w.depth_driver_m[i] =
            lo.depth_driver_m[i] + t * (hi.depth_driver_m[i] - lo.depth_driver_m[i]);
        w.depth_driven_m[i] =
            lo.depth_driven_m[i] + t * (hi.depth_driven_m[i] - lo.depth_driven_m[i]);
      }
      return std::max(w.max_depth_driver_m(), w.max_depth_driven_m());
    };
    double a = 0, b = 1;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (a + b);
      (blend(mid) < target_depth_m ? a : b) = mid;
    }
    blend(0.5 * (a + b));
    const diag::GearPair& p = gb.meshes()[static_cast<std::size_t>(mesh)].pair;
    w.te_peak_to_peak_rad = peak_to_peak(worn_gap_transmission_error(p, w, o.te_points_per_mesh));
    return w;
  }
  throw diag::InputError(
      diag::format_error("wear", "depth", "not reached within 1e15 cycles (is the pair loaded?)"));
}

std::vector<double> worn_gap_transmission_error(const diag::GearPair& pair, const WornPair& w,
                                                int points) {
  const double s0 = pair.s_start_m(), s1 = pair.s_end_m(), pb = pair.base_pitch_m();
  const double L = pair.loa_length_m(), rb2 = pair.driven().base_radius_m();
  std::vector<double> te(static_cast<std::size_t>(std::max(points, 1)));
  for (std::size_t i = 0; i < te.size(); ++i) {
    const double x = s0 + pb * (static_cast<double>(i) + 0.5) / static_cast<double>(te.size());
    double g_min = std::numeric_limits<double>::infinity();
    for (double q = x; q <= s1 + 1e-12; q += pb) {
      const double g = interp(w.roll_driver_m, w.depth_driver_m, q) +
                       interp(w.roll_driven_m, w.depth_driven_m, L - q);
      g_min = std::min(g_min, g);
    }
    te[i] = -g_min / rb2;
  }
  return te;
}

void worn_profile_gap(const diag::GearPair& pair, const WornPair& w, std::vector<double>& s_m,
                      std::vector<double>& gap_m) {
  const double L = pair.loa_length_m();
  s_m = w.roll_driver_m;
  gap_m.resize(s_m.size());
  for (std::size_t i = 0; i < s_m.size(); ++i) {
    gap_m[i] = w.depth_driver_m[i] + interp(w.roll_driven_m, w.depth_driven_m, L - s_m[i]);
  }
}

}  // namespace sim
