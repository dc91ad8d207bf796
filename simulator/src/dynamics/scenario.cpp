#include "sim/dynamics/scenario.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/json_fields.hpp"

namespace sim {

using nlohmann::json;

namespace {

std::string indexed(const std::string& key, std::size_t i) {
  return key + "[" + std::to_string(i) + "]";
}

SpeedProfile parse_speed(const json& j, const std::string& where) {
  diag::Fields f(j, where, "speed", {"rpm", "ramp", "measured"});
  const int given = f.has("rpm") + f.has("ramp") + f.has("measured");
  if (given != 1) f.fail("", "give exactly one of rpm, ramp, measured");
  if (f.has("rpm")) return SpeedProfile::constant(f.positive("rpm"));
  if (f.has("ramp")) {
    diag::Fields r(f.raw("ramp"), where, "speed.ramp",
                   {"from_rpm", "to_rpm", "start_s", "duration_s"});
    return SpeedProfile::ramp(r.positive("from_rpm"), r.positive("to_rpm"),
                              r.non_negative("start_s", 0.0), r.positive("duration_s"));
  }
  diag::Fields m(f.raw("measured"), where, "speed.measured", {"time_s", "rpm"});
  SpeedProfile p;
  p.kind = SpeedProfile::Kind::kMeasured;
  for (const char* key : {"time_s", "rpm"}) {
    if (!m.has(key) || !m.raw(key).is_array()) m.fail(key, "required array of numbers");
    for (const json& v : m.raw(key)) {
      if (!v.is_number()) m.fail(key, "must hold numbers only");
      (std::string(key) == "time_s" ? p.time_s : p.rpm_values).push_back(v.get<double>());
    }
  }
  p.validate(where + ": speed.measured");
  return p;
}

GearFault parse_fault(const json& j, const std::string& where, const std::string& path) {
  diag::Fields f(j, where, path,
                 {"gear", "tooth", "type", "depth_mm", "size_mm", "length_mm", "depth_um",
                  "width_fraction", "position_mm", "profile"});
  GearFault g;
  g.gear = f.str("gear");
  g.fault.tooth = f.integer("tooth");
  if (g.fault.tooth < 0) f.fail("tooth", "must be >= 0");
  const std::string type = f.str("type");
  g.fault.width_fraction = f.num("width_fraction", 1.0);
  if (!(g.fault.width_fraction > 0.0 && g.fault.width_fraction <= 1.0)) {
    f.fail("width_fraction", "must be in (0, 1]");
  }
  if (type == "crack") {
    g.fault.kind = ToothFault::Kind::kRootCrack;
    g.fault.size_m = f.positive("depth_mm") * 1e-3;
  } else if (type == "chip") {
    g.fault.kind = ToothFault::Kind::kChip;
    g.fault.size_m = f.positive("size_mm") * 1e-3;
  } else if (type == "missing") {
    g.fault.kind = ToothFault::Kind::kMissing;
  } else if (type == "spall") {
    g.fault.kind = ToothFault::Kind::kSpall;
    g.fault.size_m = f.positive("length_mm") * 1e-3;
    g.fault.depth_m = f.positive("depth_um") * 1e-6;
    if (f.has("position_mm")) g.fault.s_center_m = f.num("position_mm") * 1e-3;
  } else if (type == "profile") {  // a flank deviation, resolved per mesh (sim::profile_fault)
    if (!f.has("profile")) f.fail("profile", "required for type profile");
    g.profile_json = f.raw("profile").dump();
  } else {
    f.fail("type",
           "'" + type + "' is not one of crack, chip, missing, spall, profile, wear, bearing");
  }
  return g;
}

// {"type": "wear", "mesh": "A_B" | "gear": NAME, "cycles": N | "depth_um": D,
//  "law": "archard" | "seed004", "steps": K}: worn flanks of one mesh (sim::MeshWear).
MeshWear parse_wear(const json& j, const std::string& where, const std::string& path) {
  diag::Fields f(j, where, path, {"type", "gear", "mesh", "cycles", "depth_um", "law", "steps"});
  MeshWear w;
  w.where = where + ": " + path;
  if (f.has("gear") == f.has("mesh")) f.fail("mesh", "give exactly one of mesh, gear");
  w.gear = f.str("gear", "");
  w.mesh = f.str("mesh", "");
  if (f.has("cycles") == f.has("depth_um"))
    f.fail("cycles", "give exactly one of cycles, depth_um");
  if (f.has("cycles")) {
    w.cycles = f.positive("cycles");
    if (!(w.cycles <= 1e15)) f.fail("cycles", "must be <= 1e15");
  } else {
    w.depth_m = f.positive("depth_um") * 1e-6;
    if (!(w.depth_m < 1e-3)) f.fail("depth_um", "must be < 1000 um");
  }
  const std::string law = f.str("law", "archard");
  if (law != "archard" && law != "seed004")
    f.fail("law", "'" + law + "' is not archard or seed004");
  w.law = parse_wear_law(law, "law");
  if (f.has("steps")) {
    w.steps = f.integer("steps");
    if (w.steps < 1 || w.steps > 1000) f.fail("steps", "must be in [1, 1000]");
  }
  return w;
}

// {"type": "bearing", "bearing": NAME, "fault": "outer_race" | "inner_race" |
//  "rolling_element" | "cage", "amplitude_m_per_s2": A, "resonance_hz", "damping_ratio",
//  "mean_slip", "jitter"}: a localized bearing defect (sim::BearingFault).
BearingFault parse_bearing_fault(const json& j, const std::string& where, const std::string& path) {
  diag::Fields f(j, where, path,
                 {"type", "bearing", "fault", "amplitude_m_per_s2", "resonance_hz", "damping_ratio",
                  "mean_slip", "jitter"});
  BearingFault b;
  b.where = where + ": " + path;
  b.bearing = f.str("bearing");
  const std::string kind = f.str("fault");
  const std::optional<BearingFaultKind> k = bearing_fault_kind(kind);
  if (!k) f.fail("fault", "'" + kind + "' is not outer_race, inner_race, rolling_element or cage");
  b.kind = *k;
  b.amplitude_m_per_s2 = f.positive("amplitude_m_per_s2");
  if (!(b.amplitude_m_per_s2 <= 1e6)) f.fail("amplitude_m_per_s2", "must be <= 1e6 m/s^2");
  b.resonance_hz = f.positive("resonance_hz", b.resonance_hz);
  b.damping_ratio = f.positive("damping_ratio", b.damping_ratio);
  if (!(b.damping_ratio <= 0.5)) f.fail("damping_ratio", "must be in (0, 0.5]");
  b.mean_slip = f.num("mean_slip", b.mean_slip);
  if (!(std::abs(b.mean_slip) <= 0.05)) f.fail("mean_slip", "must be in [-0.05, 0.05]");
  b.jitter = f.non_negative("jitter", b.jitter);
  if (!(b.jitter <= 0.1)) f.fail("jitter", "must be in [0, 0.1]");
  return b;
}

}  // namespace

Scenario parse_scenario(const json& j, const std::string& where) {
  Scenario sc;
  DynamicsOptions& d = sc.dynamics;
  RunOptions& r = sc.run;
  diag::Fields f(j, where, "",
                 {"speed",
                  "torque_nm",
                  "motor",
                  "coupling_stiffness_nm_per_rad",
                  "mesh_damping_ratio",
                  "bearing_stiffness_n_per_m",
                  "bearing_stiffness_x_n_per_m",
                  "bearing_stiffness_y_n_per_m",
                  "bearing_damping_ratio",
                  "shaft_torsional_stiffness_nm_per_rad",
                  "backlash_um",
                  "back_flank",
                  "friction",
                  "oil",
                  "faults",
                  "accuracy_grade",
                  "runout_um",
                  "transmission_error",
                  "sensors",
                  "integrator",
                  "settle_s",
                  "duration_s",
                  "fs_hz",
                  "seed",
                  "stiffness"});
  if (f.has("speed")) d.speed = parse_speed(f.raw("speed"), where);
  d.input_torque_nm = f.has("torque_nm") ? f.non_negative("torque_nm", 0.0) : -1.0;
  const std::string motor = f.str("motor", "speed");
  if (motor == "speed") {
    d.motor = MotorMode::kSpeed;
  } else if (motor == "torque") {
    d.motor = MotorMode::kTorque;
  } else {
    f.fail("motor", "'" + motor + "' is not speed or torque");
  }
  d.coupling_stiffness_nm_per_rad = f.non_negative("coupling_stiffness_nm_per_rad", 0.0);
  d.mesh_damping_ratio = f.non_negative("mesh_damping_ratio", d.mesh_damping_ratio);
  if (f.has("bearing_stiffness_n_per_m")) {
    d.bearing_stiffness_x_n_per_m = d.bearing_stiffness_y_n_per_m =
        f.positive("bearing_stiffness_n_per_m");
  }
  d.bearing_stiffness_x_n_per_m =
      f.positive("bearing_stiffness_x_n_per_m", d.bearing_stiffness_x_n_per_m);
  d.bearing_stiffness_y_n_per_m =
      f.positive("bearing_stiffness_y_n_per_m", d.bearing_stiffness_y_n_per_m);
  d.bearing_damping_ratio = f.non_negative("bearing_damping_ratio", d.bearing_damping_ratio);
  d.shaft_torsional_stiffness_nm_per_rad =
      f.non_negative("shaft_torsional_stiffness_nm_per_rad", 0.0);
  if (f.has("backlash_um")) d.backlash_m = f.non_negative("backlash_um", 0.0) * 1e-6;
  d.back_flank = f.boolean("back_flank", true);
  if (f.has("friction")) {
    diag::Fields fr(f.raw("friction"), where, "friction", {"law", "mu", "mu_cap"});
    try {
      d.friction.law = friction_law_from_string(fr.str("law", "drozdov"));
    } catch (const diag::InputError& e) {
      fr.fail("law", e.what());
    }
    d.friction.mu_constant = fr.non_negative("mu", d.friction.mu_constant);
    d.friction.mu_cap = fr.positive("mu_cap", d.friction.mu_cap);
  }
  if (f.has("oil")) {
    diag::Fields o(f.raw("oil"), where, "oil",
                   {"iso_vg", "nu40_cst", "nu100_cst", "temperature_c"});
    if (o.has("iso_vg")) {
      try {
        d.friction.oil = Lubricant::iso_vg(o.integer("iso_vg"));
      } catch (const diag::InputError& e) {
        o.fail("iso_vg", e.what());
      }
    }
    if (o.has("nu40_cst") || o.has("nu100_cst")) {
      d.friction.oil.nu40_cst = o.positive("nu40_cst");
      d.friction.oil.nu100_cst = o.positive("nu100_cst");
    }
    d.friction.oil_temperature_c = o.num("temperature_c", d.friction.oil_temperature_c);
  }
  if (f.has("faults")) {
    if (!f.raw("faults").is_array()) f.fail("faults", "must be an array");
    const json& arr = f.raw("faults");
    for (std::size_t i = 0; i < arr.size(); ++i) {
      if (arr[i].is_object() && arr[i].value("type", json()) == "wear") {
        d.wear.push_back(parse_wear(arr[i], where, indexed("faults", i)));
      } else if (arr[i].is_object() && arr[i].value("type", json()) == "bearing") {
        r.bearing_faults.push_back(parse_bearing_fault(arr[i], where, indexed("faults", i)));
      } else {
        d.faults.push_back(parse_fault(arr[i], where, indexed("faults", i)));
      }
    }
  }
  if (f.has("accuracy_grade")) d.accuracy_grade = f.integer("accuracy_grade");
  d.runout_m = f.non_negative("runout_um", 0.0) * 1e-6;
  if (f.has("transmission_error")) {
    diag::Fields te(f.raw("transmission_error"), where, "transmission_error",
                    {"amplitude_um", "phase_deg"});
    auto numbers = [&](const char* key) {
      std::vector<double> v;
      if (!te.has(key)) return v;
      if (!te.raw(key).is_array()) te.fail(key, "must be an array of numbers (one per harmonic)");
      for (const json& x : te.raw(key)) {
        if (!x.is_number()) te.fail(key, "must hold numbers only");
        v.push_back(x.get<double>());
      }
      return v;
    };
    if (!te.has("amplitude_um")) te.fail("amplitude_um", "required (one value per harmonic)");
    for (double a : numbers("amplitude_um")) {
      if (!(a >= 0.0) || !std::isfinite(a)) te.fail("amplitude_um", "values must be >= 0");
      d.te_amplitude_m.push_back(a * 1e-6);
    }
    // Each harmonic costs a sine per mesh evaluation: 1000 is far more than any measured
    // transmission error shows (its spectrum falls off within tens of mesh orders).
    constexpr std::size_t kMaxHarmonics = 1000;
    if (d.te_amplitude_m.size() > kMaxHarmonics) {
      te.fail("amplitude_um", "more than " + std::to_string(kMaxHarmonics) + " harmonics");
    }
    for (double p : numbers("phase_deg")) {
      if (!std::isfinite(p)) te.fail("phase_deg", "values must be finite");
      d.te_phase_rad.push_back(p * std::numbers::pi / 180.0);
    }
    // Phases given must pair with the amplitudes one to one (absent: all zero).
    if (te.has("phase_deg") && d.te_phase_rad.size() != d.te_amplitude_m.size()) {
      te.fail("phase_deg",
              "has " + std::to_string(d.te_phase_rad.size()) + " entries; amplitude_um has " +
                  std::to_string(d.te_amplitude_m.size()) + " (one phase per harmonic)");
    }
  }
  // sensors.noise_seed: the sensor noise's own seed, so that two records of the same gears (the
  // same "seed": pitch errors, runout phases) differ in their noise, as two measurements do.
  std::optional<std::uint64_t> noise_seed;
  if (f.has("sensors")) {
    diag::Fields s(f.raw("sensors"), where, "sensors",
                   {"noise_m_per_s2", "casing_frequency_hz", "casing_damping_ratio",
                    "mesh_channels", "noise_seed"});
    r.accel_noise_m_per_s2 = s.non_negative("noise_m_per_s2", r.accel_noise_m_per_s2);
    r.casing_frequency_hz = s.non_negative("casing_frequency_hz", r.casing_frequency_hz);
    r.casing_damping_ratio = s.positive("casing_damping_ratio", r.casing_damping_ratio);
    r.mesh_channels = s.boolean("mesh_channels", r.mesh_channels);
    if (s.has("noise_seed")) {
      const int seed = s.integer("noise_seed");
      if (seed < 0) s.fail("noise_seed", "must be >= 0");
      noise_seed = static_cast<std::uint64_t>(seed);
    }
  }
  if (f.has("integrator")) {
    diag::Fields in(f.raw("integrator"), where, "integrator",
                    {"method", "step_s", "steps_per_period", "steps_per_mesh", "contact_substeps",
                     "rel_tol", "abs_tol"});
    const std::string method = in.str("method", "rk4");
    if (method == "rk4") {
      r.method = RunOptions::Method::kRk4;
    } else if (method == "gsl_rk8pd") {
      r.method = RunOptions::Method::kGslRk8pd;
    } else {
      in.fail("method", "'" + method + "' is not rk4 or gsl_rk8pd");
    }
    r.step_s = in.non_negative("step_s", 0.0);
    if (in.has("steps_per_period")) r.steps_per_period = in.integer("steps_per_period");
    if (in.has("steps_per_mesh")) r.steps_per_mesh = in.integer("steps_per_mesh");
    if (in.has("contact_substeps")) r.contact_substeps = in.integer("contact_substeps");
    r.gsl_rel_tol = in.positive("rel_tol", r.gsl_rel_tol);
    r.gsl_abs_tol = in.positive("abs_tol", r.gsl_abs_tol);
  }
  if (f.has("stiffness")) {
    diag::Fields st(f.raw("stiffness"), where, "stiffness", {"fillet_foundation", "tables"});
    d.stiffness.fillet_foundation = st.boolean("fillet_foundation", d.stiffness.fillet_foundation);
    if (st.has("tables")) {
      if (!st.raw("tables").is_array()) st.fail("tables", "must be an array");
      const json& arr = st.raw("tables");
      for (std::size_t i = 0; i < arr.size(); ++i) {
        const std::string path = "stiffness." + indexed("tables", i);
        diag::Fields t(arr[i], where, path, {"mesh", "angle_deg", "load_n", "k_n_per_m"});
        StiffnessTable table;
        table.mesh = t.str("mesh");
        auto numbers = [&](const json& a, const std::string& key) {
          if (!a.is_array()) t.fail(key, "must be an array of numbers");
          std::vector<double> v;
          for (const json& x : a) {
            if (!x.is_number()) t.fail(key, "must hold numbers only");
            v.push_back(x.get<double>());
          }
          return v;
        };
        if (!t.has("angle_deg") || !t.has("load_n") || !t.has("k_n_per_m")) {
          t.fail("", "needs angle_deg, load_n and k_n_per_m");
        }
        table.angle_deg = numbers(t.raw("angle_deg"), "angle_deg");
        table.load_n = numbers(t.raw("load_n"), "load_n");
        if (!t.raw("k_n_per_m").is_array()) t.fail("k_n_per_m", "must be an array of rows");
        for (const json& row : t.raw("k_n_per_m"))
          table.k_n_per_m.push_back(numbers(row, "k_n_per_m"));
        d.stiffness_tables.push_back(std::move(table));
      }
    }
  }
  if (f.has("settle_s")) r.settle_s = f.non_negative("settle_s", 0.0);
  r.duration_s = f.positive("duration_s", r.duration_s);
  r.fs_hz = f.positive("fs_hz", r.fs_hz);
  if (f.has("seed")) {
    const int seed = f.integer("seed");
    if (seed < 0) f.fail("seed", "must be >= 0");
    d.seed = r.seed = static_cast<std::uint64_t>(seed);
  }
  if (noise_seed) r.seed = *noise_seed;
  d.validate(where);
  try {
    r.validate();
  } catch (const diag::InputError& e) {
    throw diag::InputError(where + ": " + e.what());
  }
  return sc;
}

Scenario load_scenario(const std::filesystem::path& path) {
  return parse_scenario(diag::load_json_file(path), path.string());
}

}  // namespace sim
