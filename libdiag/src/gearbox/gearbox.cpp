#include "diag/gearbox/gearbox.hpp"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <numeric>
#include <queue>
#include <set>
#include <sstream>

#include "diag/error.hpp"
#include "diag/faults/fault_kind.hpp"
#include "diag/gearbox/profile_defect.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/units.hpp"
#include "diag/util/number_format.hpp"

namespace diag {

using nlohmann::json;

namespace {

const json& array_field(const json& j, const std::string& key, const std::string& where,
                        bool required) {
  static const json kEmpty = json::array();
  if (!j.contains(key) || j[key].is_null()) {
    if (required) throw InputError(format_error(where, key, "required array is missing"));
    return kEmpty;
  }
  if (!j[key].is_array()) throw InputError(format_error(where, key, "must be an array"));
  return j[key];
}

std::string indexed(const std::string& key, std::size_t i) {
  return key + "[" + std::to_string(i) + "]";
}

Material parse_material(const json& j, const std::string& where, const std::string& path) {
  Fields f(
      j, where, path,
      {"youngs_modulus_gpa", "poisson_ratio", "density_kg_m3", "hardness_hb", "roughness_ra_um"});
  Material m;
  m.youngs_modulus_pa = units::gpa_to_pa(f.positive("youngs_modulus_gpa", 206.0));
  m.poisson_ratio = f.num("poisson_ratio", m.poisson_ratio);
  if (m.poisson_ratio < 0 || m.poisson_ratio >= 0.5) f.fail("poisson_ratio", "must be in [0, 0.5)");
  m.density_kg_per_m3 = f.positive("density_kg_m3", m.density_kg_per_m3);
  m.hardness_hb = f.positive("hardness_hb", m.hardness_hb);
  m.roughness_ra_m =
      units::um_to_m(f.positive("roughness_ra_um", units::m_to_um(m.roughness_ra_m)));
  return m;
}

}  // namespace

int Gearbox::shaft_index(const std::string& name) const {
  for (std::size_t i = 0; i < shafts_.size(); ++i) {
    if (shafts_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int Gearbox::gear_index(const std::string& name) const {
  for (std::size_t i = 0; i < gears_.size(); ++i) {
    if (gears_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int Gearbox::shaft_of_gear(int gear) const { return shaft_index(gears_.at(gear).shaft); }

double Gearbox::total_ratio() const {
  return 1.0 / std::abs(shafts_.at(output_shaft_).speed_ratio);
}

double Gearbox::ratio_to_output(int gear) const {
  return std::abs(shafts_.at(shaft_of_gear(gear)).speed_ratio /
                  shafts_.at(output_shaft_).speed_ratio);
}

Gearbox Gearbox::with_input_speed_rpm(double speed_rpm) const {
  if (!(speed_rpm > 0) || !std::isfinite(speed_rpm) || speed_rpm > kMaxSpeedRpm) {
    throw InputError(format_error(name_, "input speed",
                                  format_significant(speed_rpm, 6) + " rpm is not in (0, " +
                                      format_significant(kMaxSpeedRpm, 6) + "]"));
  }
  Gearbox g = *this;
  g.input_.speed_rpm = speed_rpm;
  return g;
}

double Gearbox::shaft_speed_hz(int shaft) const {
  return units::rpm_to_hz(input_.speed_rpm) * std::abs(shafts_.at(shaft).speed_ratio);
}

double Gearbox::shaft_speed_rpm(int shaft) const {
  return input_.speed_rpm * std::abs(shafts_.at(shaft).speed_ratio);
}

double Gearbox::mesh_frequency_hz(int mesh) const {
  const Mesh& m = meshes_.at(mesh);
  return gears_[m.driver].spec.teeth * shaft_speed_hz(shaft_of_gear(m.driver));
}

double Gearbox::shaft_period_input_rev(int shaft) const {
  return 1.0 / std::abs(shafts_.at(shaft).speed_ratio);
}

double Gearbox::recurrence_period_input_rev(int gear) const {
  return shaft_period_input_rev(shaft_of_gear(gear));
}

double Gearbox::hunting_period_input_rev(int mesh) const {
  const Mesh& m = meshes_.at(mesh);
  const int z1 = gears_[m.driver].spec.teeth, z2 = gears_[m.driven].spec.teeth;
  return (z2 / std::gcd(z1, z2)) * shaft_period_input_rev(shaft_of_gear(m.driver));
}

bool Gearbox::on_power_path(int gear) const {
  for (const PathStep& p : path_) {
    if (p.up_gear == gear || p.down_gear == gear) return true;
  }
  return false;
}

std::vector<int> Gearbox::gears_sharing_shaft(int gear) const {
  return shafts_.at(shaft_of_gear(gear)).gears;
}

Gearbox parse_gearbox(const json& j, const std::string& where) {
  Gearbox gb;
  // A face-gear pair (seed 002) is its own description type, handled by the simulator's
  // sim/facegear/description.hpp; the commands that need shafts, gears and meshes refuse it here.
  if (j.is_object() && j.contains("face_gear_pair")) {
    throw InputError(format_error(where, "face_gear_pair",
                                  "a face-gear pair description: geardiag info, simulate, sweep "
                                  "and bifurcation take it; this command needs a gearbox of "
                                  "shafts, gears and meshes"));
  }
  Fields top(
      j, where, "",
      {"name", "shafts", "gears", "meshes", "input", "output", "bearings", "sensors", "defects"});
  gb.name_ = top.has("name") ? top.label("name") : "gearbox";

  // Shafts.
  const json& shafts = array_field(j, "shafts", where, true);
  if (shafts.empty()) throw InputError(format_error(where, "shafts", "needs at least one shaft"));
  for (const char* key : {"shafts", "gears", "meshes", "bearings", "defects"}) {
    if (j.contains(key) && j[key].is_array() && j[key].size() > kMaxGearboxItems) {
      throw InputError(format_error(where, key,
                                    std::to_string(j[key].size()) + " entries; at most " +
                                        std::to_string(kMaxGearboxItems) + " are supported"));
    }
  }
  for (std::size_t i = 0; i < shafts.size(); ++i) {
    Fields f(shafts[i], where, indexed("shafts", i), {"name"});
    Shaft s;
    s.name = f.name("name");
    if (gb.shaft_index(s.name) >= 0) f.fail("name", "duplicate shaft name '" + s.name + "'");
    gb.shafts_.push_back(s);
  }

  // Gears.
  const json& gears = array_field(j, "gears", where, false);
  for (std::size_t i = 0; i < gears.size(); ++i) {
    const std::string path = indexed("gears", i);
    Fields f(gears[i], where, path,
             {"name", "shaft", "teeth", "module_mm", "pressure_angle_deg", "face_width_mm",
              "profile_shift", "addendum_coefficient", "clearance_coefficient", "material",
              "bore_diameter_mm"});
    GearEntry g;
    g.name = f.name("name");
    if (gb.gear_index(g.name) >= 0) f.fail("name", "duplicate gear name '" + g.name + "'");
    g.shaft = f.str("shaft");
    const int shaft = gb.shaft_index(g.shaft);
    if (shaft < 0) f.fail("shaft", "unknown shaft '" + g.shaft + "'");
    g.spec.teeth = f.integer("teeth");
    if (g.spec.teeth <= 0)
      f.fail("teeth", "must be a positive integer (got " + std::to_string(g.spec.teeth) + ")");
    if (g.spec.teeth < 5) f.fail("teeth", "must be >= 5 for an involute spur gear");
    if (g.spec.teeth > kMaxTeeth) {
      f.fail("teeth", "must be <= " + std::to_string(kMaxTeeth) + " (got " +
                          std::to_string(g.spec.teeth) + ")");
    }
    const double module_mm = f.positive("module_mm");
    if (module_mm < kMinModuleMm || module_mm > kMaxModuleMm) {
      f.fail("module_mm", "must be in [" + format_significant(kMinModuleMm, 6) + ", " +
                              format_significant(kMaxModuleMm, 6) + "] mm (got " +
                              format_significant(module_mm, 6) + ")");
    }
    g.spec.module_m = units::mm_to_m(module_mm);
    g.spec.pressure_angle_rad = units::deg_to_rad(f.positive("pressure_angle_deg", 20.0));
    // Face width defaults to 10 modules, a common proportion, when the description omits it.
    g.spec.face_width_m =
        units::mm_to_m(f.positive("face_width_mm", 10.0 * units::m_to_mm(g.spec.module_m)));
    g.spec.profile_shift = f.num("profile_shift", 0.0);
    g.spec.addendum_coefficient = f.positive("addendum_coefficient", 1.0);
    g.spec.clearance_coefficient = f.non_negative("clearance_coefficient", 0.25);
    if (f.has("bore_diameter_mm"))
      g.spec.bore_diameter_m = units::mm_to_m(f.non_negative("bore_diameter_mm", 0.0));
    if (f.has("material"))
      g.spec.material = parse_material(f.raw("material"), where, f.sub("material"));
    validate(g.spec, format_error(where, path, ""));
    const Gear gear(g.spec);
    if (gear.undercut()) {
      std::ostringstream m;
      m << "gear '" << g.name << "' (z = " << g.spec.teeth << ", profile_shift "
        << g.spec.profile_shift << ") is undercut (no undercut from profile_shift >= "
        << format_significant(gear.min_profile_shift_without_undercut(), 6)
        << "): its involute starts at diameter "
        << format_significant(2 * units::m_to_mm(gear.form_radius_m()), 6)
        << " mm instead of the base circle ("
        << format_significant(2 * units::m_to_mm(gear.base_radius_m()), 6)
        << " mm), which shortens the contact of its meshes, and its root is thinner, so its "
           "stiffness is lower than the involute tooth model's; tooth counts, ratios and periods "
           "(attribute, kinematic simulation) are unaffected";
      gb.warnings_.push_back(format_error(where, path, m.str()));
    }
    // Tip land thinner than 0.2 m: the usual design guideline against tip chipping and through-
    // hardening of the tip (s_a >= 0.2 m to 0.4 m); a warning, the geometry is still valid.
    if (gear.tip_thickness_m() < 0.2 * g.spec.module_m) {
      gb.warnings_.push_back(format_error(
          where, path,
          "gear '" + g.name + "' has a thin tip land: " +
              format_significant(units::m_to_mm(gear.tip_thickness_m()), 6) + " mm < 0.2 modules"));
    }
    gb.shafts_[shaft].gears.push_back(static_cast<int>(gb.gears_.size()));
    gb.gears_.push_back(g);
  }

  // Meshes.
  const json& meshes = array_field(j, "meshes", where, false);
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const std::string path = indexed("meshes", i);
    Fields f(meshes[i], where, path, {"driver", "driven", "backlash_um", "centre_distance_mm"});
    MeshSpec spec;
    spec.driver = f.str("driver");
    spec.driven = f.str("driven");
    const int d = gb.gear_index(spec.driver), n = gb.gear_index(spec.driven);
    if (d < 0) f.fail("driver", "unknown gear '" + spec.driver + "'");
    if (n < 0) f.fail("driven", "unknown gear '" + spec.driven + "'");
    if (d == n) f.fail("driven", "a gear cannot mesh with itself");
    if (gb.gears_[d].shaft == gb.gears_[n].shaft) {
      f.fail("driven", "'" + spec.driver + "' and '" + spec.driven + "' are on the same shaft '" +
                           gb.gears_[d].shaft + "' and cannot mesh");
    }
    spec.backlash_m = units::um_to_m(f.non_negative("backlash_um", 0.0));
    spec.centre_distance_m = units::mm_to_m(f.non_negative("centre_distance_mm", 0.0));
    const std::string pair_where = format_error(where, path, "");
    GearPair pair(Gear(gb.gears_[d].spec), Gear(gb.gears_[n].spec), pair_where.c_str(),
                  spec.centre_distance_m);
    if (pair.contact_ratio() < pair.uncut_contact_ratio() * (1 - 1e-9)) {
      gb.warnings_.push_back(
          format_error(where, path,
                       "'" + spec.driver + "' -> '" + spec.driven + "': contact ratio " +
                           format_significant(pair.contact_ratio(), 6) + " instead of " +
                           format_significant(pair.uncut_contact_ratio(), 6) +
                           " because of the undercut (contact is lost below the form circle)"));
    }
    gb.meshes_.push_back(Mesh{d, n, spec, pair});
  }

  // Input operating point.
  if (!top.has("input")) top.fail("input", "required object is missing");
  {
    Fields f(top.raw("input"), where, "input", {"shaft", "speed_rpm", "torque_nm"});
    gb.input_.shaft = f.str("shaft");
    gb.input_shaft_ = gb.shaft_index(gb.input_.shaft);
    if (gb.input_shaft_ < 0) f.fail("shaft", "unknown shaft '" + gb.input_.shaft + "'");
    gb.input_.speed_rpm = f.positive("speed_rpm");
    if (gb.input_.speed_rpm > kMaxSpeedRpm) {
      f.fail("speed_rpm", "must be <= " + format_significant(kMaxSpeedRpm, 6) + " rpm (got " +
                              format_significant(gb.input_.speed_rpm, 6) + ")");
    }
    gb.input_.torque_nm = f.non_negative("torque_nm", 0.0);
    if (gb.input_.torque_nm > kMaxTorqueNm) {
      f.fail("torque_nm", "must be <= " + format_significant(kMaxTorqueNm, 6) + " N m");
    }
  }

  // Shaft speeds: propagate omega_driven = -omega_driver z_driver / z_driven through the meshes
  // from the input shaft, in both directions, and check that loops agree.
  std::vector<bool> known(gb.shafts_.size(), false);
  std::vector<int> via_mesh(gb.shafts_.size(), -1);  // BFS tree: the mesh that reached a shaft
  gb.shafts_[gb.input_shaft_].speed_ratio = 1.0;
  known[gb.input_shaft_] = true;
  std::queue<int> todo;
  todo.push(gb.input_shaft_);
  while (!todo.empty()) {
    const int s = todo.front();
    todo.pop();
    for (std::size_t m = 0; m < gb.meshes_.size(); ++m) {
      const Mesh& mesh = gb.meshes_[m];
      const int sd = gb.shaft_of_gear(mesh.driver), sn = gb.shaft_of_gear(mesh.driven);
      if (sd != s && sn != s) continue;
      const double zd = gb.gears_[mesh.driver].spec.teeth, zn = gb.gears_[mesh.driven].spec.teeth;
      const int other = (sd == s) ? sn : sd;
      const double r =
          (sd == s) ? -gb.shafts_[s].speed_ratio * zd / zn : -gb.shafts_[s].speed_ratio * zn / zd;
      if (known[other]) {
        constexpr double kLoopTol = 1e-9;  // relative; exact for integer tooth counts
        if (std::abs(gb.shafts_[other].speed_ratio - r) > kLoopTol * std::abs(r)) {
          throw InputError(format_error(where, indexed("meshes", m),
                                        "kinematically inconsistent loop: shaft '" +
                                            gb.shafts_[other].name +
                                            "' would turn at two different speeds"));
        }
        continue;
      }
      gb.shafts_[other].speed_ratio = r;
      known[other] = true;
      via_mesh[other] = static_cast<int>(m);
      todo.push(other);
    }
  }
  for (std::size_t s = 0; s < gb.shafts_.size(); ++s) {
    if (!known[s]) {
      throw InputError(format_error(where, indexed("shafts", s),
                                    "no gear train connects shaft '" + gb.shafts_[s].name +
                                        "' to the input shaft '" + gb.input_.shaft + "'"));
    }
  }

  // Output shaft: named, or the only shaft that drives nothing.
  if (top.has("output")) {
    Fields f(top.raw("output"), where, "output", {"shaft"});
    const std::string name = f.str("shaft");
    gb.output_shaft_ = gb.shaft_index(name);
    if (gb.output_shaft_ < 0) f.fail("shaft", "unknown shaft '" + name + "'");
  } else if (gb.shafts_.size() == 1) {
    gb.output_shaft_ = gb.input_shaft_;
  } else {
    std::vector<int> leaves;
    for (std::size_t s = 0; s < gb.shafts_.size(); ++s) {
      if (static_cast<int>(s) == gb.input_shaft_) continue;
      bool drives = false;
      for (const Mesh& m : gb.meshes_) drives |= gb.shaft_of_gear(m.driver) == static_cast<int>(s);
      if (!drives) leaves.push_back(static_cast<int>(s));
    }
    if (leaves.size() != 1) {
      std::string names;
      for (int s : leaves) names += (names.empty() ? "'" : ", '") + gb.shafts_[s].name + "'";
      top.fail("output", (leaves.empty() ? std::string("no shaft") : "shafts " + names) +
                             " could be the output: name it with \"output\": {\"shaft\": ...}");
    }
    gb.output_shaft_ = leaves.front();
  }

  // Power path: walk the BFS tree back from the output shaft.
  for (int s = gb.output_shaft_; s != gb.input_shaft_;) {
    const Mesh& mesh = gb.meshes_[via_mesh[s]];
    const bool driven_down = gb.shaft_of_gear(mesh.driven) == s;
    PathStep step{via_mesh[s], driven_down ? mesh.driver : mesh.driven,
                  driven_down ? mesh.driven : mesh.driver};
    gb.path_.insert(gb.path_.begin(), step);
    s = gb.shaft_of_gear(step.up_gear);
  }

  // Bearings.
  const json& bearings = array_field(j, "bearings", where, false);
  for (std::size_t i = 0; i < bearings.size(); ++i) {
    Fields f(bearings[i], where, indexed("bearings", i),
             {"name", "shaft", "rolling_elements", "pitch_diameter_mm", "element_diameter_mm",
              "contact_angle_deg"});
    BearingSpec b;
    b.name = f.name("name");
    for (const auto& other : gb.bearings_) {
      if (other.name == b.name) f.fail("name", "duplicate bearing name '" + b.name + "'");
    }
    b.shaft = f.str("shaft");
    if (gb.shaft_index(b.shaft) < 0) f.fail("shaft", "unknown shaft '" + b.shaft + "'");
    b.rolling_elements = f.integer("rolling_elements");
    if (b.rolling_elements < 3) f.fail("rolling_elements", "must be an integer >= 3");
    b.pitch_diameter_m = units::mm_to_m(f.positive("pitch_diameter_mm"));
    b.element_diameter_m = units::mm_to_m(f.positive("element_diameter_mm"));
    if (b.element_diameter_m >= b.pitch_diameter_m) {
      f.fail("element_diameter_mm", "must be smaller than pitch_diameter_mm");
    }
    const double angle = f.num("contact_angle_deg", 0.0);
    if (angle < 0 || angle >= 90) f.fail("contact_angle_deg", "must be in [0, 90)");
    b.contact_angle_rad = units::deg_to_rad(angle);
    gb.bearings_.push_back(b);
  }

  if (top.has("sensors") && !top.raw("sensors").is_array()) top.fail("sensors", "must be an array");

  // Defects (simulator input; also the ground truth of simulated recordings).
  const json& defects = array_field(j, "defects", where, false);
  for (std::size_t i = 0; i < defects.size(); ++i) {
    Fields f(defects[i], where, indexed("defects", i),
             {"gear", "type", "size_deg", "size_um", "tooth", "phase_deg", "profile"});
    DefectSpec d;
    d.gear = f.str("gear");
    const int g = gb.gear_index(d.gear);
    if (g < 0) f.fail("gear", "unknown gear '" + d.gear + "'");
    // The fault vocabulary (diag/faults/fault_kind.hpp): a gear kind, stored by its one name.
    d.type = std::string(diag::to_string(diag::parse_gear_fault_kind(f, "type", "chip")));
    const Gear gear(gb.gears_[g].spec);
    if (f.has("size_deg") + f.has("size_um") + f.has("profile") != 1) {
      f.fail("size_deg",
             "give exactly one of size_deg (gear rotation), size_um (along the LOA) or profile "
             "(a flank deviation)");
    }
    // A loss of size_um along the line of action is a rotation of size / r_b of this gear.
    if (f.has("profile")) {
      d.size_rad = profile_defect_loss_rad(gb, g, f.raw("profile"), where, f.sub("profile"));
    } else {
      d.size_rad = f.has("size_deg") ? units::deg_to_rad(f.positive("size_deg"))
                                     : units::um_to_m(f.positive("size_um")) / gear.base_radius_m();
    }
    // The kinematic model rolls the loss in and out within one tooth: size < half a pitch.
    if (d.size_rad >= 0.5 * gear.angular_pitch_rad()) {
      f.fail(f.has("size_deg") ? "size_deg" : "size_um",
             "must be smaller than half an angular pitch (" +
                 format_significant(units::rad_to_deg(0.5 * gear.angular_pitch_rad()), 6) +
                 " deg) of the gear");
    }
    if (f.has("tooth") && f.has("phase_deg")) f.fail("tooth", "give tooth or phase_deg, not both");
    if (f.has("tooth")) {
      d.tooth = f.integer("tooth");
      if (d.tooth < 0 || d.tooth >= gear.teeth()) {
        f.fail("tooth", "must be in [0, " + std::to_string(gear.teeth() - 1) + "]");
      }
      d.phase_rad = d.tooth * gear.angular_pitch_rad();
    } else {
      const double p = f.num("phase_deg", 0.0);
      if (p < 0 || p >= 360) f.fail("phase_deg", "must be in [0, 360)");
      d.phase_rad = units::deg_to_rad(p);
    }
    gb.defects_.push_back(d);
  }

  gb.json_text_ = j.dump(2);
  return gb;
}

Gearbox parse_gearbox_text(const std::string& text, const std::string& where) {
  return parse_gearbox(parse_json_text(text, where), where);
}

Gearbox load_gearbox(const std::filesystem::path& path) {
  return parse_gearbox(load_json_file(path), path.string());
}

json summary_json(const Gearbox& gb) {
  json out;
  out["name"] = gb.name();
  out["input_shaft"] = gb.shafts()[gb.input_shaft()].name;
  out["output_shaft"] = gb.shafts()[gb.output_shaft()].name;
  out["input_speed_rpm"] = gb.input().speed_rpm;
  out["input_torque_nm"] = gb.input().torque_nm;
  out["total_ratio"] = gb.total_ratio();
  out["shafts"] = json::array();
  for (std::size_t s = 0; s < gb.shafts().size(); ++s) {
    json js;
    js["name"] = gb.shafts()[s].name;
    js["speed_rpm"] = gb.shaft_speed_rpm(s);
    js["frequency_hz"] = gb.shaft_speed_hz(s);
    js["direction"] = gb.shafts()[s].speed_ratio > 0 ? "same as input" : "opposite to input";
    js["ratio_to_input"] = 1.0 / std::abs(gb.shafts()[s].speed_ratio);
    js["ratio_to_output"] =
        std::abs(gb.shafts()[s].speed_ratio / gb.shafts()[gb.output_shaft()].speed_ratio);
    js["period_input_rev"] = gb.shaft_period_input_rev(s);
    js["gears"] = json::array();
    for (int g : gb.shafts()[s].gears) js["gears"].push_back(gb.gears()[g].name);
    out["shafts"].push_back(js);
  }
  out["gears"] = json::array();
  for (std::size_t g = 0; g < gb.gears().size(); ++g) {
    json jg;
    jg["name"] = gb.gears()[g].name;
    jg["shaft"] = gb.gears()[g].shaft;
    jg["teeth"] = gb.gears()[g].spec.teeth;
    jg["ratio_to_output"] = gb.ratio_to_output(g);
    jg["recurrence_period_input_rev"] = gb.recurrence_period_input_rev(g);
    out["gears"].push_back(jg);
  }
  out["meshes"] = json::array();
  for (std::size_t m = 0; m < gb.meshes().size(); ++m) {
    const Mesh& mesh = gb.meshes()[m];
    json jm;
    jm["driver"] = gb.gears()[mesh.driver].name;
    jm["driven"] = gb.gears()[mesh.driven].name;
    jm["ratio"] = mesh.pair.ratio();
    jm["mesh_frequency_hz"] = gb.mesh_frequency_hz(m);
    jm["contact_ratio"] = mesh.pair.contact_ratio();
    jm["centre_distance_mm"] = units::m_to_mm(mesh.pair.centre_distance_m());
    jm["working_pressure_angle_deg"] = units::rad_to_deg(mesh.pair.working_pressure_angle_rad());
    jm["hunting_period_input_rev"] = gb.hunting_period_input_rev(m);
    out["meshes"].push_back(jm);
  }
  out["bearings"] = json::array();
  for (const auto& b : gb.bearings()) {
    out["bearings"].push_back({{"name", b.name},
                               {"shaft", b.shaft},
                               {"rolling_elements", b.rolling_elements},
                               {"pitch_diameter_mm", units::m_to_mm(b.pitch_diameter_m)},
                               {"element_diameter_mm", units::m_to_mm(b.element_diameter_m)},
                               {"contact_angle_deg", units::rad_to_deg(b.contact_angle_rad)}});
  }
  out["warnings"] = gb.warnings();
  out["defects"] = json::array();
  for (const auto& d : gb.defects()) {
    out["defects"].push_back({{"gear", d.gear},
                              {"type", d.type},
                              {"size_deg", units::rad_to_deg(d.size_rad)},
                              {"phase_deg", units::rad_to_deg(d.phase_rad)}});
  }
  return out;
}

std::string format_summary(const Gearbox& gb) {
  std::ostringstream o;
  o << std::setprecision(6);
  o << "gearbox '" << gb.name() << "': input shaft '" << gb.shafts()[gb.input_shaft()].name
    << "' at " << gb.input().speed_rpm << " rpm, " << gb.input().torque_nm << " N m; output shaft '"
    << gb.shafts()[gb.output_shaft()].name << "'; overall ratio u = " << gb.total_ratio() << "\n\n";
  o << "shafts:\n";
  o << "  name            speed_rpm   freq_hz     period_input_rev  gears\n";
  for (std::size_t s = 0; s < gb.shafts().size(); ++s) {
    std::string gears;
    for (int g : gb.shafts()[s].gears) gears += (gears.empty() ? "" : ", ") + gb.gears()[g].name;
    o << "  " << std::left << std::setw(16) << gb.shafts()[s].name << std::setw(12)
      << gb.shaft_speed_rpm(s) << std::setw(12) << gb.shaft_speed_hz(s) << std::setw(18)
      << gb.shaft_period_input_rev(s) << (gears.empty() ? "-" : gears) << "\n";
  }
  if (!gb.meshes().empty()) {
    o << "\nmeshes:\n";
    o << "  driver -> driven        ratio     mesh_freq_hz  contact_ratio  "
         "hunting_period_input_rev\n";
    for (std::size_t m = 0; m < gb.meshes().size(); ++m) {
      const Mesh& mesh = gb.meshes()[m];
      const std::string label =
          gb.gears()[mesh.driver].name + " -> " + gb.gears()[mesh.driven].name;
      o << "  " << std::left << std::setw(24) << label << std::setw(10) << mesh.pair.ratio()
        << std::setw(14) << gb.mesh_frequency_hz(m) << std::setw(15) << mesh.pair.contact_ratio()
        << gb.hunting_period_input_rev(m) << "\n";
    }
  }
  if (!gb.gears().empty()) {
    o << "\ngears (defect recurrence period T_i = 2 pi u_total / u_i, seed 003 eq. 5 corrected):\n";
    o << "  name        shaft           teeth  u_i (to output)  T_i [input rev]  T_i [deg]\n";
    for (std::size_t g = 0; g < gb.gears().size(); ++g) {
      o << "  " << std::left << std::setw(12) << gb.gears()[g].name << std::setw(16)
        << gb.gears()[g].shaft << std::setw(7) << gb.gears()[g].spec.teeth << std::setw(17)
        << gb.ratio_to_output(g) << std::setw(17) << gb.recurrence_period_input_rev(g)
        << 360.0 * gb.recurrence_period_input_rev(g) << "\n";
    }
  }
  if (!gb.bearings().empty()) {
    o << "\nbearings:\n";
    for (const auto& b : gb.bearings()) {
      o << "  " << b.name << " on '" << b.shaft << "': " << b.rolling_elements << " elements, P_d "
        << units::m_to_mm(b.pitch_diameter_m) << " mm, B_d " << units::m_to_mm(b.element_diameter_m)
        << " mm, contact angle " << units::rad_to_deg(b.contact_angle_rad) << " deg\n";
    }
  }
  if (!gb.defects().empty()) {
    o << "\ndefects:\n";
    for (const auto& d : gb.defects()) {
      o << "  " << d.type << " on '" << d.gear << "': " << units::rad_to_deg(d.size_rad)
        << " deg of gear rotation at gear angle " << units::rad_to_deg(d.phase_rad) << " deg\n";
    }
  }
  return o.str();
}

}  // namespace diag
