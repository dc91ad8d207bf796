#include "diag/geometry/profile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "diag/error.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/units.hpp"

namespace diag {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Polar {
  double r, psi;
};

// The gear-frame point cut by the rack point (u, v) with normal direction (nu, nv): the meshing
// equation of the header, then the rack position seen from the gear.
Polar envelope_point(double u, double v, double nu, double nv, double r) {
  const double phi = (u + (r - v) * nu / nv) / r;
  const double a = u - r * phi;
  const double gx = std::cos(phi) * a + std::sin(phi) * v;
  const double gy = -std::sin(phi) * a + std::cos(phi) * v;
  return {std::hypot(gx, gy), std::atan2(gx, gy)};
}

// Smallest psi of the polylines `branches` at radius r (+inf when none spans r).
double min_crossing(const std::vector<std::vector<Polar>>& branches, double r) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& b : branches) {
    for (std::size_t i = 1; i < b.size(); ++i) {
      const double r0 = b[i - 1].r, r1 = b[i].r;
      if ((r < std::min(r0, r1)) || (r > std::max(r0, r1))) continue;
      const double t = r1 == r0 ? 0.0 : (r - r0) / (r1 - r0);
      best = std::min(best, b[i - 1].psi + t * (b[i].psi - b[i - 1].psi));
    }
  }
  return best;
}

double interp(std::span<const double> x, std::span<const double> y, double xq) {
  if (x.empty() || xq < x.front() || xq > x.back()) return kNaN;
  const auto it = std::upper_bound(x.begin(), x.end(), xq);
  if (it == x.end()) return y.back();
  const std::size_t i = static_cast<std::size_t>(it - x.begin());
  if (i == 0) return y.front();
  const double t = (xq - x[i - 1]) / (x[i] - x[i - 1]);
  return y[i - 1] + t * (y[i] - y[i - 1]);
}

}  // namespace

void ProfileOptions::validate(const GearSpec& g, const std::string& where) const {
  const double rho_max = g.clearance_coefficient / (1.0 - std::sin(g.pressure_angle_rad));
  if (!(rack_tip_radius_coefficient >= 0 && rack_tip_radius_coefficient <= rho_max + 1e-3)) {
    std::ostringstream m;
    m << "must be in [0, c*/(1 - sin(alpha))] = [0, " << rho_max << "] (got "
      << rack_tip_radius_coefficient << ")";
    throw InputError(format_error(where, "rack_tip_radius_coefficient", m.str()));
  }
  if (!(chord_tolerance_m > 0 && chord_tolerance_m < 1e-4)) {
    throw InputError(format_error(where, "chord_tolerance_m", "must be in (0, 1e-4) m"));
  }
  if (fillet_points < 16) {
    throw InputError(format_error(where, "fillet_points", "must be >= 16"));
  }
}

double Flank::half_angle_at(double r) const { return interp(radius_m, half_angle_rad, r); }

double involute_half_angle(const Gear& gear, double r) {
  const GearSpec& s = gear.spec();
  const double s_over_d =
      (0.5 * units::kPi + 2.0 * s.profile_shift * std::tan(s.pressure_angle_rad)) / s.teeth;
  const double c = std::min(1.0, gear.base_radius_m() / r);
  return s_over_d + involute(s.pressure_angle_rad) - involute(std::acos(c));
}

GeneratedTooth generate_tooth(const Gear& gear, const ProfileOptions& options) {
  const GearSpec& s = gear.spec();
  options.validate(s, "profile options");
  const double m = s.module_m, alpha = s.pressure_angle_rad, x = s.profile_shift;
  const double r = gear.pitch_radius_m(), rb = gear.base_radius_m(), ra = gear.tip_radius_m();
  const double sin_a = std::sin(alpha), cos_a = std::cos(alpha), tan_a = std::tan(alpha);
  const double Y = r + x * m;              // datum line of the rack
  const double c = 0.25 * units::kPi * m;  // cutter flank at the datum
  const double D = (s.addendum_coefficient + s.clearance_coefficient) * m;  // cutter tip depth
  const double rho = options.rack_tip_radius_coefficient * m;
  // Tip arc centre (depth D - rho, distance rho from the flank inside the cutter tooth).
  const double dc = D - rho;
  const double uc = c + (rho + dc * sin_a) / cos_a, vc = Y - dc;
  if (uc > 0.5 * units::kPi * m) {
    throw InputError(format_error("profile options", "rack_tip_radius_coefficient",
                                  "the tip arc does not fit on the cutter tooth"));
  }
  const double d_t1 = D - rho * (1.0 - sin_a);  // depth where the straight flank ends
  // Roll distance on the gear of the point cut by the flank at depth d (contact on the generating
  // line of action): rho_g = r sin(alpha) - (d - x m) / sin(alpha).
  const double rho_t1 = r * sin_a - (d_t1 - x * m) / sin_a;
  const double rho_top = std::sqrt(ra * ra - rb * rb);

  // Involute candidates: adaptive spacing so that a chord departs from the curve (radius of
  // curvature |rho_g|) by at most the tolerance: step = sqrt(8 |rho_g| tol).
  std::vector<Polar> inv;
  std::vector<double> inv_roll;
  const double floor_rho = 1e-3 * m, max_step = m / 40.0;
  for (double rg = rho_t1;;) {
    const double d = x * m + (r * sin_a - rg) * sin_a;
    inv.push_back(envelope_point(c + d * tan_a, Y - d, cos_a, sin_a, r));
    inv_roll.push_back(rg);
    if (rg >= rho_top) break;
    const double step = std::min(
        max_step, std::sqrt(8.0 * std::max(std::abs(rg), floor_rho) * options.chord_tolerance_m));
    rg = std::min(rho_top, rg + step);
  }
  // Fillet candidates: the tip arc from the flank (t = pi + alpha) to the tip line (3 pi / 2).
  std::vector<Polar> fil;
  const int nf = options.fillet_points;
  for (int i = nf; i >= 0; --i) {  // root upward
    const double t = units::kPi + alpha + (0.5 * units::kPi - alpha) * i / nf;
    const double nu = std::cos(t), nv = std::sin(t);
    if (rho > 0) fil.push_back(envelope_point(uc + rho * nu, vc + rho * nv, nu, nv, r));
  }
  if (rho == 0) {
    // A sharp cutter corner at (c + D tan(alpha), Y - D) traces a trochoid; sample it over the
    // rack positions around its deepest pass.
    const double u0 = c + D * tan_a, v0 = Y - D;
    fil.clear();
    for (int i = 0; i <= 4 * nf; ++i) {
      const double phi = u0 / r - 0.5 * gear.angular_pitch_rad() * i / (4.0 * nf);
      const double a = u0 - r * phi;
      const double gx = std::cos(phi) * a + std::sin(phi) * v0;
      const double gy = -std::sin(phi) * a + std::cos(phi) * v0;
      fil.push_back({std::hypot(gx, gy), std::atan2(gx, gy)});
    }
  }

  // Keep what the rack leaves: at each radius the smallest half angle over both envelopes.
  const std::vector<std::vector<Polar>> branches = {fil, inv};
  constexpr double kKeepTol = 1e-12;  // [rad], round-off of the crossing interpolation
  std::vector<Polar> kept;
  for (const Polar& p : fil) {
    if (p.psi >= 0 && p.psi <= min_crossing(branches, p.r) + kKeepTol) kept.push_back(p);
  }
  std::size_t first_inv = inv.size();
  for (std::size_t i = 0; i < inv.size(); ++i) {
    const Polar& p = inv[i];
    if (p.r > ra * (1 + 1e-12) || inv_roll[i] < 0) continue;
    if (p.psi <= min_crossing(branches, p.r) + kKeepTol) {
      kept.push_back(p);
      first_inv = std::min(first_inv, i);
    }
  }
  if (first_inv == inv.size()) {
    throw InputError(format_error("gear", "teeth", "the rack leaves no involute on the tooth"));
  }
  std::sort(kept.begin(), kept.end(), [](const Polar& a, const Polar& b) { return a.r < b.r; });

  GeneratedTooth out;
  out.involute_start_radius_m = std::hypot(rb, std::max(rho_t1, 0.0));
  out.involute_removed_m = std::max(0.0, inv_roll[first_inv] - std::max(rho_t1, 0.0));
  // Any removal beyond round-off is the undercut (at z = 17, x = 0, just below z_min = 17.1,
  // it is 0.3 um of roll at m = 3 mm).
  constexpr double kRemovedTol = 1e-9;  // [m] envelope points are exact to ~1e-15 relative
  out.undercut = out.involute_removed_m > kRemovedTol;
  Flank& f = out.flank;
  f.base_radius_m = rb;
  f.form_radius_m = inv[first_inv].r;
  for (const Polar& p : kept) {
    if (!f.radius_m.empty() && p.r <= f.radius_m.back() * (1 + 1e-14)) continue;
    f.radius_m.push_back(p.r);
    f.half_angle_rad.push_back(p.psi);
  }
  return out;
}

std::vector<std::array<double, 2>> tooth_outline(const Gear& gear, const Flank& driving,
                                                 const Flank& other, int tooth) {
  const double half_pitch = 0.5 * gear.angular_pitch_rad();
  const double turn = -tooth * gear.angular_pitch_rad();
  std::vector<std::array<double, 2>> pts;
  auto add = [&](double r, double psi) {  // psi measured from the centre line towards +x
    const double a = psi - turn;
    pts.push_back({r * std::sin(a), r * std::cos(a)});
  };
  constexpr int kArc = 16;
  // Root land before the tooth (-x side), the -x flank upward, tip land, +x flank down, root land.
  const double rf_o = other.radius_m.front(), psi_fo = other.half_angle_rad.front();
  for (int i = 0; i < kArc; ++i) add(rf_o, -half_pitch + (half_pitch - psi_fo) * i / kArc);
  for (std::size_t i = 0; i < other.radius_m.size(); ++i) {
    add(other.radius_m[i], -other.half_angle_rad[i]);
  }
  const double psi_to = other.half_angle_rad.back(), psi_td = driving.half_angle_rad.back();
  const double rt_o = other.top_radius_m(), rt_d = driving.top_radius_m();
  for (int i = 1; i < kArc; ++i) {
    const double t = static_cast<double>(i) / kArc;
    add(rt_o + (rt_d - rt_o) * t, -psi_to + (psi_to + psi_td) * t);
  }
  for (std::size_t i = driving.radius_m.size(); i-- > 0;) {
    add(driving.radius_m[i], driving.half_angle_rad[i]);
  }
  const double rf_d = driving.radius_m.front(), psi_fd = driving.half_angle_rad.front();
  for (int i = 1; i <= kArc; ++i) add(rf_d, psi_fd + (half_pitch - psi_fd) * i / kArc);
  return pts;
}

Flank apply_normal_depth(const Flank& flank, std::span<const double> roll_m,
                         std::span<const double> depth_m) {
  Flank out = flank;
  const double rb = flank.base_radius_m;
  const std::size_t n = flank.radius_m.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double r = flank.radius_m[i];
    if (r <= rb) continue;
    const double rg = std::sqrt(r * r - rb * rb);
    const double d = interp(roll_m, depth_m, rg);
    if (!(std::abs(d) > 0)) continue;  // outside (NaN) or zero
    const std::size_t lo = i > 0 ? i - 1 : i, hi = i + 1 < n ? i + 1 : i;
    const double slope = (flank.half_angle_rad[hi] - flank.half_angle_rad[lo]) /
                         (flank.radius_m[hi] - flank.radius_m[lo]);
    out.half_angle_rad[i] -= d * std::sqrt(1.0 + (r * slope) * (r * slope)) / r;
  }
  return out;
}

Flank apply_defect(const Flank& flank, const ProfileDefect& d, const std::string& where) {
  const double rb = flank.base_radius_m;
  const double top = flank.top_radius_m();
  auto roll_of = [&](double r) { return std::sqrt(std::max(0.0, r * r - rb * rb)); };
  switch (d.kind) {
    case ProfileDefect::Kind::kChip:
    case ProfileDefect::Kind::kPit: {
      const double rho0 = rb * d.roll_start_rad, rho1 = rb * d.roll_end_rad;
      const double rho_form = roll_of(flank.form_radius_m), rho_top = roll_of(top);
      constexpr double kRollTol = 1e-9;  // [m] a range given as the flank's ends
      if (!(rho0 >= rho_form - kRollTol && rho1 <= rho_top + kRollTol && rho1 > rho0)) {
        std::ostringstream m;
        m << "must lie on the involute, within [" << units::rad_to_deg(rho_form / rb) << ", "
          << units::rad_to_deg(rho_top / rb) << "] deg of roll, start < end";
        throw InputError(format_error(where, "roll_deg", m.str()));
      }
      // Arc length along the involute from the base circle: sigma = rho^2 / (2 r_b).
      const double s0 = rho0 * rho0 / (2 * rb), s1 = rho1 * rho1 / (2 * rb);
      const bool to_top = rho1 >= rho_top - kRollTol;
      std::vector<double> roll, depth;
      constexpr int kN = 400;
      for (int i = 0; i <= kN; ++i) {
        const double sg = s0 + (s1 - s0) * i / kN;
        double v;
        if (d.kind == ProfileDefect::Kind::kPit) {
          v = d.depth_m * std::sin(units::kPi * (sg - s0) / (s1 - s0));
        } else {
          const double wall = d.depth_m;  // 45 deg walls
          v = d.depth_m * std::min({1.0, (sg - s0) / wall, to_top ? 1.0 : (s1 - sg) / wall});
          if (i == 0 && !(s1 - s0 > 0)) v = 0;
        }
        roll.push_back(std::sqrt(2 * rb * sg));
        depth.push_back(std::max(0.0, v));
      }
      if (to_top) roll.back() = rho_top * (1 + 1e-12);
      Flank out = apply_normal_depth(flank, roll, depth);
      for (std::size_t i = 0; i < out.radius_m.size(); ++i) {
        if (out.half_angle_rad[i] < -flank.half_angle_rad[i]) {
          throw InputError(format_error(where, "depth_um", "removes more than the whole tooth"));
        }
      }
      return out;
    }
    case ProfileDefect::Kind::kBrokenTip: {
      if (!(d.break_radius_m > flank.form_radius_m && d.break_radius_m < top)) {
        std::ostringstream m;
        m << "must lie between the form diameter " << units::m_to_mm(2 * flank.form_radius_m)
          << " mm and the flank's top " << units::m_to_mm(2 * top) << " mm";
        throw InputError(format_error(where, "break_diameter_mm", m.str()));
      }
      Flank out = flank;
      out.radius_m.clear();
      out.half_angle_rad.clear();
      for (std::size_t i = 0; i < flank.radius_m.size() && flank.radius_m[i] < d.break_radius_m;
           ++i) {
        out.radius_m.push_back(flank.radius_m[i]);
        out.half_angle_rad.push_back(flank.half_angle_rad[i]);
      }
      out.radius_m.push_back(d.break_radius_m);
      out.half_angle_rad.push_back(flank.half_angle_at(d.break_radius_m));
      return out;
    }
    case ProfileDefect::Kind::kContour: {
      if (d.contour_m.size() < 2) {
        throw InputError(format_error(where, "contour_mm", "needs at least 2 points"));
      }
      std::vector<Polar> c;
      for (std::size_t i = 0; i < d.contour_m.size(); ++i) {
        const double r = std::hypot(d.contour_m[i][0], d.contour_m[i][1]);
        const double psi = std::atan2(d.contour_m[i][0], d.contour_m[i][1]);
        const std::string field = "contour_mm[" + std::to_string(i) + "]";
        if (!(r >= flank.radius_m.front() && r <= top)) {
          throw InputError(format_error(where, field,
                                        "lies outside the tooth (radius beyond the root or the "
                                        "top of the flank)"));
        }
        const double healthy = flank.half_angle_at(r);
        constexpr double kInsideTol = 1e-9;  // [rad] a point on the flank itself is inside
        if (!(psi <= healthy + kInsideTol && psi > -healthy)) {
          throw InputError(format_error(where, field, "lies outside the tooth"));
        }
        if (!c.empty() && !(r > c.back().r)) {
          throw InputError(
              format_error(where, field, "radii must increase strictly from the root to the tip"));
        }
        c.push_back({r, psi});
      }
      Flank out = flank;
      out.radius_m.clear();
      out.half_angle_rad.clear();
      auto push = [&](double r, double psi) {
        if (!out.radius_m.empty() && r <= out.radius_m.back()) return;
        out.radius_m.push_back(r);
        out.half_angle_rad.push_back(psi);
      };
      for (std::size_t i = 0; i < flank.radius_m.size() && flank.radius_m[i] < c.front().r; ++i) {
        push(flank.radius_m[i], flank.half_angle_rad[i]);
      }
      for (const Polar& p : c) push(p.r, p.psi);
      for (std::size_t i = 0; i < flank.radius_m.size(); ++i) {
        if (flank.radius_m[i] > c.back().r) push(flank.radius_m[i], flank.half_angle_rad[i]);
      }
      return out;
    }
  }
  return flank;
}

ProfileDefect parse_profile_defect(const nlohmann::json& j, const Gear& gear, const Flank& flank,
                                   const std::string& where, const std::string& path) {
  Fields f(j, where, path, {"kind", "roll_deg", "depth_um", "break_diameter_mm", "contour_mm"});
  ProfileDefect d;
  const std::string kind = f.str("kind");
  if (kind == "chip" || kind == "pit") {
    d.kind = kind == "chip" ? ProfileDefect::Kind::kChip : ProfileDefect::Kind::kPit;
    d.depth_m = units::um_to_m(f.positive("depth_um"));
    const nlohmann::json& roll = f.raw("roll_deg");
    if (!roll.is_array() || roll.size() != 2 || !roll[0].is_number() || !roll[1].is_number()) {
      f.fail("roll_deg", "must be [start, end] in degrees of roll angle");
    }
    d.roll_start_rad = units::deg_to_rad(roll[0].get<double>());
    d.roll_end_rad = units::deg_to_rad(roll[1].get<double>());
  } else if (kind == "broken_tip") {
    d.kind = ProfileDefect::Kind::kBrokenTip;
    d.break_radius_m = 0.5 * units::mm_to_m(f.positive("break_diameter_mm"));
  } else if (kind == "contour") {
    d.kind = ProfileDefect::Kind::kContour;
    const nlohmann::json& c = f.raw("contour_mm");
    if (!c.is_array()) f.fail("contour_mm", "must be an array of [x, y] points in mm");
    constexpr std::size_t kMaxContourPoints = 10000;  // rolling cost grows with the points
    if (c.size() > kMaxContourPoints) f.fail("contour_mm", "has more than 10000 points");
    for (const auto& p : c) {
      if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) {
        f.fail("contour_mm", "must be an array of [x, y] points in mm");
      }
      d.contour_m.push_back(
          {units::mm_to_m(p[0].get<double>()), units::mm_to_m(p[1].get<double>())});
    }
  } else {
    f.fail("kind", "must be chip, pit, broken_tip or contour (got '" + kind + "')");
  }
  (void)gear;
  // Applying it checks it against the tooth (throws naming the field).
  apply_defect(flank, d, path.empty() ? where : where + ": " + path);
  return d;
}

std::vector<double> unloaded_transmission_error(const GearPair& pair, const MeshFlanks& flanks,
                                                std::span<const double> driver_angles) {
  const int z1 = pair.driver().teeth(), z2 = pair.driven().teeth();
  if (static_cast<int>(flanks.driver.size()) != z1 ||
      static_cast<int>(flanks.driven.size()) != z2) {
    throw InputError(format_error("unloaded_transmission_error", "flanks",
                                  "need one flank per tooth of each gear"));
  }
  const double tau1 = units::kTwoPi / z1, tau2 = units::kTwoPi / z2, u = pair.ratio();
  const double a = pair.centre_distance_m();
  // A driver tooth can touch the driven gear only while its tip circle point lies within the
  // driven tip circle: |centre angle| < gamma_max + its half angle (+ a margin for broken or
  // deviating teeth, which only shrink).
  const double ra1 = pair.driver().tip_radius_m(), ra2 = pair.driven().tip_radius_m();
  const double gamma_max =
      std::acos(std::clamp((ra1 * ra1 + a * a - ra2 * ra2) / (2 * ra1 * a), -1.0, 1.0)) +
      0.5 * tau1;
  // Flank vertices as local Cartesian vectors, once per distinct flank: the driver's driving
  // flank at +psi counter-clockwise from the centre line (+y), the driven's contacted flank at
  // -psi from its centre line (-y), both for a tooth centred at angle 0.
  struct Local {
    std::vector<double> x, y;
  };
  std::vector<std::pair<const Flank*, Local>> cache;
  auto local_of = [&](const Flank* f, bool driver) -> const Local& {
    for (const auto& [key, loc] : cache) {
      if (key == f) return loc;
    }
    Local l;
    for (std::size_t i = 0; i < f->radius_m.size(); ++i) {
      const double r = f->radius_m[i], p = f->half_angle_rad[i];
      l.x.push_back(driver ? -r * std::sin(p) : r * std::sin(p));
      l.y.push_back(driver ? r * std::cos(p) : -r * std::cos(p));
    }
    cache.emplace_back(f, std::move(l));
    return cache.back().second;
  };
  for (const auto& f : flanks.driver) local_of(f.get(), true);
  for (const auto& f : flanks.driven) local_of(f.get(), false);

  std::vector<double> te(driver_angles.size());
  for (std::size_t n = 0; n < driver_angles.size(); ++n) {
    const double phi1 = driver_angles[n];
    const double nominal = phi1 / u + 0.5 * tau2;
    const double lo = nominal - 0.5 * tau2, hi = nominal + 0.5 * tau2;
    double best = lo;
    const long k0 = static_cast<long>(std::floor(phi1 / tau1));
    for (long k = k0 - 2; k <= k0 + 3; ++k) {
      const double g1 = phi1 - k * tau1;  // driver tooth centre, counter-clockwise from +y
      if (std::abs(g1) > gamma_max) continue;
      const Flank* p1 = flanks.driver[static_cast<std::size_t>(((k % z1) + z1) % z1)].get();
      const Flank* p2 = flanks.driven[static_cast<std::size_t>(((k % z2) + z2) % z2)].get();
      const Flank &f1 = *p1, &f2 = *p2;
      const Local &l1 = local_of(p1, true), &l2 = local_of(p2, false);
      const double top2 = f2.top_radius_m(), root2 = f2.radius_m.front();
      const double top1 = f1.top_radius_m(), root1 = f1.radius_m.front();
      // (a) driver vertices against the driven flank: closed form. Vertices nearer the driver's
      // centre than a - top2 cannot reach the driven tooth.
      const double c1 = std::cos(g1), s1 = std::sin(g1);
      const auto first1 = static_cast<std::size_t>(
          std::lower_bound(f1.radius_m.begin(), f1.radius_m.end(), a - top2) - f1.radius_m.begin());
      for (std::size_t i = first1; i < f1.radius_m.size(); ++i) {
        const double qx = l1.x[i] * c1 - l1.y[i] * s1, qy = l1.x[i] * s1 + l1.y[i] * c1 - a;
        const double R2 = qx * qx + qy * qy;
        if (R2 > top2 * top2 || R2 < root2 * root2) continue;
        const double th = std::atan2(-qx, -qy) + f2.half_angle_at(std::sqrt(R2)) + k * tau2;
        if (th > best && th < hi) best = th;
      }
      // (b) driven vertices against the driver flank: the driver angle of contact is closed form
      // for a given driven angle; the driven angle that makes it phi1 by the secant method, run
      // to convergence only for vertices whose first secant estimate can beat the best so far.
      const auto first2 = static_cast<std::size_t>(
          std::lower_bound(f2.radius_m.begin(), f2.radius_m.end(), a - top1) - f2.radius_m.begin());
      struct Turn {
        double c, s;
      };
      auto turn = [&](double th) {
        const double b = th - k * tau2;
        return Turn{std::cos(b), std::sin(b)};
      };
      double rp = 0;
      auto contact_phi1 = [&](std::size_t i, const Turn& t) {
        const double px = l2.x[i] * t.c + l2.y[i] * t.s;
        const double py = a - l2.x[i] * t.s + l2.y[i] * t.c;
        rp = std::hypot(px, py);
        return std::atan2(-px, py) - f1.half_angle_at(rp) + k * tau1 - phi1;
      };
      const double ta = nominal, tb = nominal - 1e-4 * tau2;
      const Turn turn_a = turn(ta), turn_b = turn(tb);
      for (std::size_t i = first2; i < f2.radius_m.size(); ++i) {
        double t0 = ta, f0 = contact_phi1(i, turn_a);
        if (!std::isfinite(f0)) continue;  // outside the driver flank's radii
        double t1 = tb, fv = contact_phi1(i, turn_b);
        if (!std::isfinite(fv) || fv == f0) continue;
        constexpr double kScreen = 1e-3;  // [rad] a first estimate this far below cannot win
        if (t1 - fv * (t1 - t0) / (fv - f0) < best - kScreen) continue;
        for (int it = 0; it < 20 && std::abs(t1 - t0) > 1e-15; ++it) {
          const double t2 = t1 - fv * (t1 - t0) / (fv - f0);
          t0 = t1;
          f0 = fv;
          t1 = t2;
          fv = contact_phi1(i, turn(t1));
          if (!std::isfinite(fv) || fv == f0) break;
        }
        if (!(std::abs(fv) <= 1e-12) || !(rp >= root1 && rp <= top1)) continue;
        if (t1 > best && t1 < hi) best = t1;
      }
    }
    te[n] = best - nominal;
  }
  return te;
}

double defect_angular_loss_rad(const GearPair& pair, bool on_driver, const ProfileDefect& defect,
                               const ProfileOptions& options, int steps_per_pitch) {
  if (steps_per_pitch < 20) {
    throw InputError(format_error("defect_angular_loss_rad", "steps_per_pitch", "must be >= 20"));
  }
  const auto h1 = std::make_shared<const Flank>(generate_tooth(pair.driver(), options).flank);
  const auto h2 = std::make_shared<const Flank>(generate_tooth(pair.driven(), options).flank);
  MeshFlanks mf{std::vector<std::shared_ptr<const Flank>>(pair.driver().teeth(), h1),
                std::vector<std::shared_ptr<const Flank>>(pair.driven().teeth(), h2)};
  const Flank& base = on_driver ? *h1 : *h2;
  auto bad = std::make_shared<const Flank>(apply_defect(base, defect, "profile defect"));
  (on_driver ? mf.driver : mf.driven)[0] = bad;
  // Pair 0 is centred on the line of centres at phi1 = 0; it is in contact within eps / 2 driver
  // pitches either side, and a lag it opens lasts at most one pitch longer.
  const double tau1 = pair.driver().angular_pitch_rad();
  const int span =
      static_cast<int>(std::ceil((0.5 * pair.contact_ratio() + 1.0) * steps_per_pitch));
  std::vector<double> phi;
  for (int i = -span; i <= span; ++i) {
    phi.push_back(tau1 * i / steps_per_pitch);
  }
  const std::vector<double> te = unloaded_transmission_error(pair, mf, phi);
  const double lag = -*std::min_element(te.begin(), te.end());
  return std::max(0.0, lag) * (on_driver ? pair.ratio() : 1.0);
}

}  // namespace diag

namespace diag {

double generated_contact_ratio(const GearPair& pair, const ProfileOptions& options) {
  const Gear &g1 = pair.driver(), &g2 = pair.driven();
  const double rb1 = g1.base_radius_m(), rb2 = g2.base_radius_m(), L = pair.loa_length_m();
  const double f1 = generate_tooth(g1, options).flank.form_radius_m;
  const double f2 = generate_tooth(g2, options).flank.form_radius_m;
  const double start = std::max(L - std::sqrt(std::pow(g2.tip_radius_m(), 2) - rb2 * rb2),
                                std::sqrt(f1 * f1 - rb1 * rb1));
  const double end = std::min(std::sqrt(std::pow(g1.tip_radius_m(), 2) - rb1 * rb1),
                              L - std::sqrt(f2 * f2 - rb2 * rb2));
  return (end - start) / pair.base_pitch_m();
}

}  // namespace diag
