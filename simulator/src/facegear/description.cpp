#include "sim/facegear/description.hpp"

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <sstream>

#include "diag/error.hpp"
#include "diag/io/hdf5.hpp"
#include "diag/io/hdf5_arrays.hpp"
#include "diag/io/input_file.hpp"
#include "diag/io/json_fields.hpp"

namespace sim::facegear {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kSteelDensity = 7800.0;     // [kg/m^3], the seed's SAE 9310
constexpr double kCGamma = 20.0e9;           // ISO 6336-1 mean mesh stiffness [N/m per m]
constexpr double kGearRimThickness = 15e-3;  // assumed face-gear rim thickness [m]

double deg(double d) { return d * kPi / 180.0; }

}  // namespace

double Geometry::pinion_pitch_radius_m() const {
  return normal_module_m * pinion_teeth / (2.0 * std::cos(helix_angle_rad));
}

double Geometry::gear_mean_radius_m() const {
  return 0.5 * (gear_inner_radius_m + gear_outer_radius_m);
}

double default_pinion_inertia(const Geometry& g) {
  const double r = g.pinion_pitch_radius_m();
  return 0.5 * kSteelDensity * kPi * std::pow(r, 4) * g.pinion_face_width_m;
}

double default_gear_inertia(const Geometry& g) {
  const double ro = g.gear_outer_radius_m, ri = g.gear_inner_radius_m;
  return 0.5 * kSteelDensity * kPi * (std::pow(ro, 4) - std::pow(ri, 4)) * kGearRimThickness;
}

void analytic_tables(const Geometry& g, double te_drive_um, double te_coast_um, FlankTable& drive,
                     FlankTable& coast) {
  const double rp = g.pinion_pitch_radius_m();
  const double alpha_t =
      std::atan(std::tan(g.normal_pressure_angle_rad) / std::cos(g.helix_angle_rad));
  const double r_base = rp * std::cos(alpha_t);
  const double rm = g.gear_mean_radius_m();
  const double width = std::min(g.gear_face_width_m, g.pinion_face_width_m);
  // Pinion torque per face-gear radian: F = k_L delta, delta = dphi_2 R_m cos(alpha_n) along the
  // tooth normal, T_1 = F r_b.
  const double k_rated = kCGamma * width * r_base * rm * std::cos(g.normal_pressure_angle_rad);
  const double period = 2.0 * kPi / g.pinion_teeth;
  const int na = 32;
  // Dense at light load, where the point contact's T^(1/3) bends most (the seed's 12 N m case).
  const std::vector<double> loads = {0.1, 0.3, 1, 3, 6, 12, 25, 50, 100, 200, 300, 400};
  struct Shape {
    double mean, a1, a2, phase, te_um, te_phase;
  };
  const Shape shapes[2] = {{1.0, 0.08, 0.02, 0.0, te_drive_um, 0.0},
                           {0.95, 0.10, 0.03, kPi / 3.0, te_coast_um, kPi / 2.0}};
  FlankTable* tabs[2] = {&drive, &coast};
  for (int f = 0; f < 2; ++f) {
    FlankTable& t = *tabs[f];
    const Shape& s = shapes[f];
    t.angle_rad.clear();
    t.k.clear();
    t.e0_rad.clear();
    t.load_nm = loads;
    for (int i = 0; i < na; ++i) {
      const double a = period * i / na;
      const double x = g.pinion_teeth * a;  // mesh phase
      t.angle_rad.push_back(a);
      t.e0_rad.push_back(s.te_um * 1e-6 / rm * std::cos(x + s.te_phase));
      const double shape =
          s.mean * (1.0 + s.a1 * std::cos(x + s.phase) + s.a2 * std::cos(2.0 * x + 2.0 * s.phase));
      for (double load : loads) {
        // Hertz point contact (header): secant stiffness ~ T^(1/3), the ISO value at rated load.
        const double low = std::cbrt(load / kRatedTorqueNm);
        t.k.push_back(k_rated * shape * low);
      }
    }
  }
}

void load_table_csv(const std::filesystem::path& path, const FaceGearPair& pair, FlankTable& drive,
                    FlankTable& coast) {
  const std::string where = path.string();
  // A regular file of at most 64 MiB without NUL bytes (diag/io/input_file.hpp): a FIFO or a
  // device is refused before it is opened. Messages name fields, never echo the file's text.
  std::istringstream in(diag::read_input_file(path, "", std::uint64_t{64} << 20));
  std::string line;
  if (!std::getline(in, line)) diag::fail(where, "", "empty stiffness table");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "flank,angle_deg,load_nm,stiffness_nm_per_rad,e0_urad") {
    diag::fail(where, "header",
               "the first line must be 'flank,angle_deg,load_nm,stiffness_nm_per_rad,e0_urad'");
  }
  // Per flank: (angle, load) -> k, angle -> e0.
  std::map<std::string, std::map<std::pair<double, double>, double>> k;
  std::map<std::string, std::map<double, double>> e0;
  int lineno = 1;
  while (std::getline(in, line)) {
    ++lineno;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (lineno > 1000000) diag::fail(where, "", "more than 1e6 rows");
    // Exactly 5 fields: a row with more is refused, not cut.
    std::string cells[5];
    std::size_t nc = 0, from = 0;
    for (;; ++nc) {
      const std::size_t comma = line.find(',', from);
      if (nc < 5) cells[nc] = line.substr(from, comma == std::string::npos ? comma : comma - from);
      if (comma == std::string::npos) break;
      from = comma + 1;
    }
    ++nc;
    const std::string at = "line " + std::to_string(lineno);
    if (nc != 5) {
      diag::fail(where, at, std::to_string(nc) + " comma-separated fields; exactly 5 are needed");
    }
    const std::string& flank = cells[0];
    if (flank != "drive" && flank != "coast") {
      diag::fail(where, at + ": flank", "must be drive or coast");
    }
    double v[4];
    static const char* names[4] = {"angle_deg", "load_nm", "stiffness_nm_per_rad", "e0_urad"};
    for (int i = 0; i < 4; ++i) {
      char* end = nullptr;
      v[i] = std::strtod(cells[i + 1].c_str(), &end);
      if (end == cells[i + 1].c_str() || *end != '\0' || !std::isfinite(v[i])) {
        diag::fail(where, at + ": " + names[i], "not a finite number");
      }
    }
    if (!(v[2] > 0)) {
      diag::fail(where, at + ": stiffness_nm_per_rad",
                 "must be > 0 (got " + std::to_string(v[2]) + ")");
    }
    if (!k[flank].emplace(std::make_pair(v[0], v[1]), v[2]).second) {
      diag::fail(where, at, "duplicate (angle, load) for flank " + flank);
    }
    auto [it, fresh] = e0[flank].emplace(v[0], v[3]);
    if (!fresh && it->second != v[3]) {
      diag::fail(where, at + ": e0_urad", "differs from an earlier row of the same angle");
    }
  }
  FlankTable* tabs[2] = {&drive, &coast};
  const char* names[2] = {"drive", "coast"};
  for (int f = 0; f < 2; ++f) {
    FlankTable& t = *tabs[f];
    t = FlankTable{};
    if (k[names[f]].empty()) diag::fail(where, names[f], "no rows for this flank");
    std::set<double> loads;
    for (const auto& [key, value] : k[names[f]]) loads.insert(key.second);
    t.load_nm.assign(loads.begin(), loads.end());
    for (const auto& [angle, e] : e0[names[f]]) {
      t.angle_rad.push_back(angle * kPi / 180.0);
      t.e0_rad.push_back(e * 1e-6);
      for (double load : t.load_nm) {
        auto it = k[names[f]].find({angle, load});
        if (it == k[names[f]].end()) {
          diag::fail(where, names[f],
                     "the grid is incomplete: no row for angle " + std::to_string(angle) +
                         " deg, load " + std::to_string(load) + " N m");
        }
        t.k.push_back(it->second);
      }
    }
    t.validate(where, names[f], pair.mesh_period_rad());
  }
}

void load_table_hdf5(const std::filesystem::path& path, const FaceGearPair& pair, FlankTable& drive,
                     FlankTable& coast) {
  const std::string where = path.string();
  const char* flanks[2] = {"drive", "coast"};
  const char* grids[2] = {"angle_deg", "load_nm"};
  std::vector<std::string> names = {"/angle_deg", "/load_nm"};
  for (const char* f : flanks) {
    for (const char* leaf : {"angle_deg", "load_nm", "stiffness_nm_per_rad", "e0_urad"}) {
      names.push_back(std::string("/") + f + "/" + leaf);
    }
  }
  const std::map<std::string, diag::Hdf5Array> arrays = diag::read_hdf5_arrays(path, names);
  const double period = pair.mesh_period_rad();
  FlankTable* tabs[2] = {&drive, &coast};
  for (int f = 0; f < 2; ++f) {
    const std::string flank = flanks[f];
    auto find = [&](const std::string& name) -> const diag::Hdf5Array* {
      auto it = arrays.find(name);
      return it == arrays.end() ? nullptr : &it->second;
    };
    // The flank's own grid, else the shared one at the root.
    const diag::Hdf5Array* grid[2];
    for (int g = 0; g < 2; ++g) {
      const std::string own = "/" + flank + "/" + grids[g], shared = std::string("/") + grids[g];
      grid[g] = find(own);
      if (grid[g] == nullptr) grid[g] = find(shared);
      if (grid[g] == nullptr) {
        diag::fail(where, shared, "missing dataset (nor " + own + " for the " + flank + " flank)");
      }
      if (grid[g]->shape.size() != 1) diag::fail(where, grid[g]->path, "must be 1-D");
    }
    const diag::Hdf5Array* k = find("/" + flank + "/stiffness_nm_per_rad");
    const diag::Hdf5Array* e0 = find("/" + flank + "/e0_urad");
    if (k == nullptr) diag::fail(where, "/" + flank + "/stiffness_nm_per_rad", "missing dataset");
    if (e0 == nullptr) diag::fail(where, "/" + flank + "/e0_urad", "missing dataset");
    const std::vector<double>& angle = grid[0]->data;
    const std::vector<double>& load = grid[1]->data;
    const std::size_t na = angle.size(), nl = load.size();
    const std::vector<std::size_t> want = {na, nl};
    if (k->shape != want) {
      std::string got;
      for (std::size_t d : k->shape) got += (got.empty() ? "" : " x ") + std::to_string(d);
      diag::fail(where, k->path,
                 "shape " + got + " does not match " + grid[0]->path + " x " + grid[1]->path +
                     " (" + std::to_string(na) + " x " + std::to_string(nl) + ")");
    }
    if (e0->shape != std::vector<std::size_t>{na}) {
      diag::fail(where, e0->path, "must be 1-D with one value per angle of " + grid[0]->path);
    }
    FlankTable& t = *tabs[f];
    t = FlankTable{};
    for (std::size_t i = 0; i < na; ++i) {
      const double a = angle[i] * kPi / 180.0;
      if (a < 0 || a >= period) {
        diag::fail(where, grid[0]->path,
                   "angle " + std::to_string(angle[i]) + " deg is outside one mesh period [0, " +
                       std::to_string(360.0 / pair.pinion_teeth) + ")");
      }
      if (i > 0 && !(angle[i] > angle[i - 1])) {
        diag::fail(where, grid[0]->path,
                   "angles must be strictly increasing (entry " + std::to_string(i) + ": " +
                       std::to_string(angle[i]) + " after " + std::to_string(angle[i - 1]) + ")");
      }
      t.angle_rad.push_back(a);
      t.e0_rad.push_back(e0->data[i] * 1e-6);
    }
    for (std::size_t j = 0; j < nl; ++j) {
      if (load[j] < 0 || (j > 0 && !(load[j] > load[j - 1]))) {
        diag::fail(where, grid[1]->path,
                   "loads must be >= 0 and strictly increasing (entry " + std::to_string(j) + ")");
      }
    }
    for (std::size_t i = 0; i < k->data.size(); ++i) {
      if (!(k->data[i] > 0)) {
        diag::fail(where, k->path,
                   "stiffness must be > 0 (got " + std::to_string(k->data[i]) + " at angle " +
                       std::to_string(angle[i / nl]) + " deg, load " +
                       std::to_string(load[i % nl]) + " N m)");
      }
    }
    t.load_nm = load;
    t.k = k->data;
    t.validate(where, flank, period);
  }
}

void load_table(const std::filesystem::path& path, const FaceGearPair& pair, FlankTable& drive,
                FlankTable& coast) {
  if (diag::is_hdf5_file(path)) {
    load_table_hdf5(path, pair, drive, coast);
  } else {
    load_table_csv(path, pair, drive, coast);
  }
}

bool is_face_gear(const nlohmann::json& j) { return j.is_object() && j.contains("face_gear_pair"); }

bool is_face_gear_file(const std::filesystem::path& path) {
  return is_face_gear(diag::load_json_file(path));
}

namespace {

void parse_pair(const nlohmann::json& j, const std::string& where, Description& d) {
  diag::Fields f(j, where, "face_gear_pair",
                 {"pinion_teeth",
                  "gear_teeth",
                  "normal_module_mm",
                  "normal_pressure_angle_deg",
                  "helix_angle_deg",
                  "gear_inner_radius_mm",
                  "gear_outer_radius_mm",
                  "gear_inner_diameter_mm",
                  "gear_outer_diameter_mm",
                  "pinion_face_width_mm",
                  "gear_face_width_mm",
                  "pinion_inertia_kg_m2",
                  "gear_inertia_kg_m2",
                  "backlash_um",
                  "mesh_damping_ratio",
                  "damping_alpha",
                  "damping_beta",
                  "bearing_damping_nms",
                  "stiffness_table",
                  "stiffness_scale",
                  "static_te_um"});
  Geometry& g = d.geometry;
  g.pinion_teeth = f.integer("pinion_teeth");
  g.gear_teeth = f.integer("gear_teeth");
  if (g.pinion_teeth < 5 || g.pinion_teeth > 200) f.fail("pinion_teeth", "must be in [5, 200]");
  if (g.gear_teeth <= g.pinion_teeth || g.gear_teeth > 1000) {
    f.fail("gear_teeth", "must be greater than pinion_teeth and at most 1000");
  }
  g.normal_module_m = f.positive("normal_module_mm", 2.75) * 1e-3;
  g.normal_pressure_angle_rad = deg(f.positive("normal_pressure_angle_deg", 27.5));
  if (g.normal_pressure_angle_rad >= deg(45)) f.fail("normal_pressure_angle_deg", "must be < 45");
  g.helix_angle_rad = deg(f.non_negative("helix_angle_deg", 15.0));
  if (g.helix_angle_rad >= deg(45)) f.fail("helix_angle_deg", "must be < 45");
  for (const char* old : {"gear_inner_diameter_mm", "gear_outer_diameter_mm"}) {
    if (f.has(old)) {
      f.fail(old,
             "the seed's L1, L2 are the face gear's inner and outer radii (L2 - L1 is its face "
             "width): give gear_inner_radius_mm and gear_outer_radius_mm");
    }
  }
  g.gear_inner_radius_m = f.positive("gear_inner_radius_mm", 160.52) * 1e-3;
  g.gear_outer_radius_m = f.positive("gear_outer_radius_mm", 190.04) * 1e-3;
  if (g.gear_outer_radius_m <= g.gear_inner_radius_m) {
    f.fail("gear_outer_radius_mm", "must exceed gear_inner_radius_mm");
  }
  g.pinion_face_width_m = f.positive("pinion_face_width_mm", 34.52) * 1e-3;
  g.gear_face_width_m = f.positive("gear_face_width_mm", 29.52) * 1e-3;
  FaceGearPair& p = d.pair;
  p.pinion_teeth = g.pinion_teeth;
  p.gear_teeth = g.gear_teeth;
  p.inertia_p = f.positive("pinion_inertia_kg_m2", default_pinion_inertia(g));
  p.inertia_g = f.positive("gear_inertia_kg_m2", default_gear_inertia(g));
  const double backlash_m = f.num("backlash_um", 50.0) * 1e-6;
  if (!(backlash_m >= 0)) f.fail("backlash_um", "must be >= 0");
  p.half_backlash_rad = 0.5 * backlash_m / g.pinion_pitch_radius_m();
  p.stiffness_scale = f.positive("stiffness_scale", 1.0);
  if (f.has("bearing_damping_nms")) {
    const nlohmann::json& b = f.raw("bearing_damping_nms");
    if (!b.is_array() || b.size() != 2 || !b[0].is_number() || !b[1].is_number() ||
        !(b[0].get<double>() >= 0) || !(b[1].get<double>() >= 0)) {
      f.fail("bearing_damping_nms", "must be [c_p, c_g], two numbers >= 0 [N m s/rad]");
    }
    p.bearing_damping_p = b[0].get<double>();
    p.bearing_damping_g = b[1].get<double>();
  } else {
    p.bearing_damping_p = 1e-3;
    p.bearing_damping_g = 1e-2;
  }
  double te[2] = {2.0, 3.0};
  if (f.has("static_te_um")) {
    const nlohmann::json& t = f.raw("static_te_um");
    if (!t.is_array() || t.size() != 2 || !t[0].is_number() || !t[1].is_number() ||
        !(t[0].get<double>() >= 0) || !(t[1].get<double>() >= 0)) {
      f.fail("static_te_um", "must be [drive, coast], two amplitudes >= 0 [um]");
    }
    te[0] = t[0].get<double>();
    te[1] = t[1].get<double>();
  }
  d.table_source = f.str("stiffness_table", "analytic");
  if (d.table_source == "analytic") {
    analytic_tables(g, te[0], te[1], p.drive, p.coast);
  } else {
    if (f.has("static_te_um")) {
      f.fail("static_te_um", "the static TE comes from the table file (e0_urad); remove it");
    }
    std::filesystem::path tp(d.table_source);
    if (tp.is_relative()) tp = std::filesystem::path(where).parent_path() / tp;
    load_table(tp, p, p.drive, p.coast);
  }
  d.mesh_damping_ratio = f.non_negative("mesh_damping_ratio", 0.05);
  if (f.has("damping_alpha") || f.has("damping_beta")) {
    if (f.has("mesh_damping_ratio"))
      f.fail("mesh_damping_ratio", "give it or alpha/beta, not both");
    p.damping_alpha = f.non_negative("damping_alpha", 0.0);
    p.damping_beta = f.non_negative("damping_beta", 0.0);
  } else {
    // Stiffness-proportional: zeta at the rated load's mesh mode (beta = 2 zeta / omega_n).
    p.damping_alpha = 0.0;
    p.damping_beta =
        2.0 * d.mesh_damping_ratio / (2.0 * kPi * p.natural_frequency_hz(kRatedTorqueNm));
  }
}

}  // namespace

Description parse_description(const nlohmann::json& j, const std::string& where) {
  Description d;
  diag::Fields top(j, where, "", {"name", "face_gear_pair", "input", "torque_fluctuation"});
  if (top.has("name")) d.name = top.label("name");
  if (!top.has("face_gear_pair")) top.fail("face_gear_pair", "required object is missing");
  parse_pair(top.raw("face_gear_pair"), where, d);
  if (top.has("input")) {
    diag::Fields f(top.raw("input"), where, "input", {"speed_rpm", "torque_nm"});
    d.operating.speed_rpm = f.positive("speed_rpm", 4000.0);
    d.operating.torque_nm = f.positive("torque_nm", 300.0);
    if (d.operating.speed_rpm > 1e5) f.fail("speed_rpm", "at most 1e5 rpm");
  }
  if (top.has("torque_fluctuation")) {
    diag::Fields f(top.raw("torque_fluctuation"), where, "torque_fluctuation",
                   {"input_amplitude", "input_frequency_hz", "input_phase_deg", "load_amplitude",
                    "load_frequency_hz", "load_phase_deg"});
    Operating& o = d.operating;
    o.input_amp = f.non_negative("input_amplitude", 0.0);
    o.input_freq_hz = f.non_negative("input_frequency_hz", 0.0);
    o.input_phase_rad = deg(f.num("input_phase_deg", 0.0));
    o.load_amp = f.non_negative("load_amplitude", 0.0);
    o.load_freq_hz = f.non_negative("load_frequency_hz", 0.0);
    o.load_phase_rad = deg(f.num("load_phase_deg", 0.0));
    if (o.input_amp >= 1) f.fail("input_amplitude", "must be < 1 (the torque keeps its sign)");
    if (o.load_amp >= 1) f.fail("load_amplitude", "must be < 1 (the torque keeps its sign)");
  }
  return d;
}

Description load_description(const std::filesystem::path& path) {
  return parse_description(diag::load_json_file(path), path.string());
}

void apply_scenario(Description& d, const nlohmann::json& sc, const std::string& where) {
  diag::Fields f(sc, where, "", {"stiffness_scale", "torque_nm", "backlash_um", "static_te_scale"});
  d.pair.stiffness_scale *= f.positive("stiffness_scale", 1.0);
  d.operating.torque_nm = f.positive("torque_nm", d.operating.torque_nm);
  if (f.has("backlash_um")) {
    const double b = f.num("backlash_um") * 1e-6;
    if (!(b >= 0)) f.fail("backlash_um", "must be >= 0");
    d.pair.half_backlash_rad = 0.5 * b / d.geometry.pinion_pitch_radius_m();
  }
  const double te = f.non_negative("static_te_scale", 1.0);
  for (FlankTable* t : {&d.pair.drive, &d.pair.coast}) {
    for (double& e : t->e0_rad) e *= te;
  }
}

}  // namespace sim::facegear
