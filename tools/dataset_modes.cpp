#include "dataset_modes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <set>
#include <stdexcept>
#include <string_view>

#include "detect/gear/sidebands.hpp"
#include "diag/error.hpp"
#include "diag/faults/fault_kind.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/units.hpp"
#include "diag/util/number_format.hpp"
#include "facegear_cmd.hpp"
#include "sim/facegear/description.hpp"
#include "sim/kinematic/sporadic_defects.hpp"

namespace geardiag {

namespace {

using diag::units::deg_to_rad;
using diag::units::rad_to_deg;
using nlohmann::json;
namespace fg = sim::facegear;

// Kinematic datasets: what sim::simulate_kinematic needs (its defaults).
constexpr double kDefaultStepRad = 0.001;  // KinematicOptions::step_rad
constexpr double kStepsPerPulse = 24;      // auto step: the simulator requires >= 20
constexpr double kMaxSamples = 5e7;        // the simulator's bound

// The spec's resolved path of gearbox b.
std::filesystem::path resolve(const DatasetSpec& s, const std::string& p) {
  std::filesystem::path path = p;
  return path.is_relative() ? s.file.parent_path() / path : path;
}

// Power-path gears of gb (a defect elsewhere never reaches the output angle).
std::vector<int> path_gears(const diag::Gearbox& gb) {
  std::vector<int> out;
  for (std::size_t g = 0; g < gb.gears().size(); ++g) {
    if (gb.on_power_path(static_cast<int>(g))) out.push_back(static_cast<int>(g));
  }
  return out;
}

std::vector<int> candidates(const KinematicDefect& d, const diag::Gearbox& gb) {
  if (d.gears.empty()) return path_gears(gb);
  std::vector<int> out;
  for (const std::string& name : d.gears) out.push_back(gb.gear_index(name));
  return out;
}

// Input revolutions of a kinematic recording on gb: the spec's, else the simulator's default
// (six periods of the slowest path shaft: five complete recurrences after any first event).
double kinematic_revolutions(const DatasetSpec& s, const diag::Gearbox& gb) {
  if (s.kinematic.revolutions > 0) return s.kinematic.revolutions;
  double longest = 1.0;
  longest = std::max(longest, gb.shaft_period_input_rev(gb.input_shaft()));
  for (const diag::PathStep& st : gb.power_path()) {
    longest = std::max(longest, gb.shaft_period_input_rev(gb.shaft_of_gear(st.down_gear)));
  }
  return 6.0 * longest;
}

// A defect's pulse in input angle [rad]: hold + recovery, each its own size, times T_i
// (sporadic_defects.hpp).
double pulse_input_rad(const diag::Gearbox& gb, int g, double size_gear_rad) {
  return 2.0 * size_gear_rad * gb.recurrence_period_input_rev(g);
}

KinematicDefect parse_defect(const json& j, const std::string& where, const std::string& path) {
  const diag::Fields f(j, where, path,
                       {"gear", "type", "size_deg", "size_output_deg", "phase_deg"});
  KinematicDefect d;
  d.gears = names_or_any(f, "gear", "gear name");
  // The gearbox description's rule: a gear kind of the vocabulary, by its one name, refused
  // here, before anything is written, rather than by the simulator per recording.
  d.type = std::string(diag::to_string(diag::parse_gear_fault_kind(f, "type", "chip")));
  if (f.has("size_deg") == f.has("size_output_deg")) {
    f.fail("size_deg",
           "give exactly one of size_deg (the gear's own rotation) or "
           "size_output_deg (at the output shaft)");
  }
  d.size_at_output = f.has("size_output_deg");
  d.size_deg = parse_range(f, d.size_at_output ? "size_output_deg" : "size_deg", 0, 90, true);
  if (f.has("phase_deg") && !(f.raw("phase_deg").is_string() && f.raw("phase_deg") == "any")) {
    d.any_phase = false;
    d.phase_deg = parse_range(f, "phase_deg", 0, 360, false);
    if (d.phase_deg.hi >= 360) f.fail("phase_deg", "must be below 360");
  }
  return d;
}

// Everything the kinematic simulator would refuse, at the extremes of every range: a gear no
// gearbox has or off the power path, a size not below half a pitch, a step too coarse for the
// smallest pulse, too many samples.
void check_kinematic(const DatasetSpec& s) {
  const std::string where = s.file.string();
  for (std::size_t b = 0; b < s.gearboxes.size(); ++b) {
    const diag::Gearbox& gb = s.gearboxes[b];
    double smallest_pulse = INFINITY;
    for (std::size_t c = 0; c < s.classes.size(); ++c) {
      for (std::size_t i = 0; i < s.classes[c].defects.size(); ++i) {
        const KinematicDefect& d = s.classes[c].defects[i];
        const std::string field = indexed("classes", c) + "." + indexed("defects", i);
        for (const std::string& name : d.gears) {
          const int g = gb.gear_index(name);
          if (g < 0) {
            diag::fail(where, field + ".gear",
                       "'" + name + "' is not a gear of " + s.gearbox_paths[b]);
          }
          if (!gb.on_power_path(g)) {
            diag::fail(where, field + ".gear",
                       "'" + name + "' of " + s.gearbox_paths[b] +
                           " is not on the power path: its defect never reaches the output angle");
          }
        }
        for (int g : candidates(d, gb)) {
          const double u = d.size_at_output ? gb.ratio_to_output(g) : 1.0;
          const double half_pitch = 0.5 * diag::Gear(gb.gears()[g].spec).angular_pitch_rad();
          if (!(deg_to_rad(d.size_deg.hi * u) < half_pitch)) {
            diag::fail(where, field + (d.size_at_output ? ".size_output_deg" : ".size_deg"),
                       diag::format_significant(d.size_deg.hi * u, 6) + " deg at gear '" +
                           gb.gears()[g].name + "' of " + s.gearbox_paths[b] +
                           " is not below half its angular pitch (" +
                           diag::format_significant(rad_to_deg(half_pitch), 6) +
                           " deg): the model rolls a defect in and out within one tooth");
          }
          smallest_pulse =
              std::min(smallest_pulse, pulse_input_rad(gb, g, deg_to_rad(d.size_deg.lo * u)));
        }
      }
    }
    double step = s.kinematic.step_deg > 0 ? deg_to_rad(s.kinematic.step_deg) : kDefaultStepRad;
    if (std::isfinite(smallest_pulse)) {
      if (s.kinematic.step_deg > 0 && step > smallest_pulse / 20) {
        diag::fail(where, "kinematic.step_deg",
                   diag::format_significant(s.kinematic.step_deg, 6) +
                       " deg is too coarse for the smallest defect on " + s.gearbox_paths[b] +
                       ": its pulse spans " +
                       diag::format_significant(rad_to_deg(smallest_pulse), 6) +
                       " deg of input angle; use step_deg <= " +
                       diag::format_significant(rad_to_deg(smallest_pulse / 20), 6) +
                       " (or leave it out)");
      }
      if (s.kinematic.step_deg <= 0) step = std::min(step, smallest_pulse / kStepsPerPulse);
    }
    const double samples = kinematic_revolutions(s, gb) * diag::units::kTwoPi / step;
    if (!(samples <= kMaxSamples)) {
      diag::fail(
          where, "kinematic.revolutions",
          diag::format_significant(kinematic_revolutions(s, gb), 6) + " input revolutions of " +
              s.gearbox_paths[b] + " at a step of " +
              diag::format_significant(rad_to_deg(step), 6) + " deg need " +
              diag::format_significant(samples, 6) +
              " samples, more than 5e7: fewer revolutions, larger defects or a coarser step");
    }
  }
}

// operating_points and face_gear fields (of the spec or of a class) into `r`.
void parse_face_gear_fields(const diag::Fields& f, FaceGearRanges& r) {
  if (f.has("operating_points")) {
    const diag::Fields op(f.raw("operating_points"), f.where(), f.sub("operating_points"),
                          {"speed_rpm", "torque_nm"});
    if (op.has("speed_rpm")) r.speed_rpm = parse_range(op, "speed_rpm", 0, 1e5, true);
    if (op.has("torque_nm")) r.torque_nm = parse_range(op, "torque_nm", 0, 1e6, true);
  }
  if (!f.has("face_gear")) return;
  const diag::Fields g(f.raw("face_gear"), f.where(), f.sub("face_gear"),
                       {"backlash_um", "stiffness_scale", "static_te_scale", "torque_fluctuation"});
  if (g.has("backlash_um")) {
    r.has_backlash = true;
    r.backlash_um = parse_range(g, "backlash_um", 0, 1e4, false);
  }
  if (g.has("stiffness_scale")) r.stiffness_scale = parse_range(g, "stiffness_scale", 0, 1e3, true);
  if (g.has("static_te_scale"))
    r.static_te_scale = parse_range(g, "static_te_scale", 0, 1e3, false);
  if (g.has("torque_fluctuation")) {
    const diag::Fields t(
        g.raw("torque_fluctuation"), f.where(), g.sub("torque_fluctuation"),
        {"input_amplitude", "input_frequency_hz", "load_amplitude", "load_frequency_hz"});
    r.has_fluctuation = true;
    for (const auto& [key, range] :
         {std::pair<const char*, Range*>{"input_amplitude", &r.input_amplitude},
          {"load_amplitude", &r.load_amplitude}}) {
      if (!t.has(key)) continue;
      *range = parse_range(t, key, 0, 1, false);
      if (range->hi >= 1) t.fail(key, "must be < 1 (the torque keeps its sign)");
    }
    for (const auto& [key, range] :
         {std::pair<const char*, Range*>{"input_frequency_hz", &r.input_frequency_hz},
          {"load_frequency_hz", &r.load_frequency_hz}}) {
      if (t.has(key)) *range = parse_range(t, key, 0, 1e5, false);
    }
  }
}

// A face-gear description with one recording's values (see draw_face_gear).
json face_gear_model(const json& desc, double rpm, double torque, const FaceGearRanges& fr,
                     double backlash, double stiffness, double ia, double ifr, double la,
                     double lf) {
  json m = desc;
  m["input"] = {{"speed_rpm", rpm}, {"torque_nm", torque}};
  if (fr.has_backlash) m["face_gear_pair"]["backlash_um"] = backlash;
  m["face_gear_pair"]["stiffness_scale"] =
      desc["face_gear_pair"].value("stiffness_scale", 1.0) * stiffness;
  if (fr.has_fluctuation) {
    json& t = m["torque_fluctuation"];
    if (!t.is_object()) t = json::object();
    t["input_amplitude"] = ia;
    t["input_frequency_hz"] = ifr;
    t["load_amplitude"] = la;
    t["load_frequency_hz"] = lf;
  }
  return m;
}

// Each class's extremes through the face-gear model, and the sampling rate.
void check_face_gear(const DatasetSpec& s) {
  const std::string where = s.file.string();
  const int harmonics = detect::SidebandOptions{}.mesh_harmonics;
  for (std::size_t c = 0; c < s.classes.size(); ++c) {
    const FaceGearRanges& r = s.classes[c].face_gear;
    const std::string field = indexed("classes", c);
    if (!(r.speed_rpm.hi > 0)) {
      diag::fail(where, field + ".operating_points.speed_rpm",
                 "required (in the class or the spec's operating_points)");
    }
    if (!(r.torque_nm.hi > 0)) {
      diag::fail(where, field + ".operating_points.torque_nm",
                 "required (in the class or the spec's operating_points)");
    }
    for (std::size_t b = 0; b < s.gearbox_json.size(); ++b) {
      const int np = s.gearbox_json[b]["face_gear_pair"].value("pinion_teeth", 0);
      const double f = harmonics * np * r.speed_rpm.hi / 60.0;
      if (s.fs_hz < 2.5 * f) {
        diag::fail(where, "fs_hz",
                   diag::format_significant(s.fs_hz, 6) + " Hz is below 2.5 x " +
                       diag::format_significant(f, 6) + " Hz, mesh harmonic " +
                       std::to_string(harmonics) + " of " + s.gearbox_paths[b] + " at " +
                       diag::format_significant(r.speed_rpm.hi, 6) + " rpm (class " +
                       s.classes[c].name +
                       "); use fs_hz >= " + diag::format_significant(std::ceil(2.5 * f), 6));
      }
      for (const bool hi : {false, true}) {
        auto v = [&](const Range& x) { return hi ? x.hi : x.lo; };
        const json m =
            face_gear_model(s.gearbox_json[b], v(r.speed_rpm), v(r.torque_nm), r, v(r.backlash_um),
                            v(r.stiffness_scale), v(r.input_amplitude), v(r.input_frequency_hz),
                            v(r.load_amplitude), v(r.load_frequency_hz));
        try {
          const fg::Description d = fg::parse_description(m, s.gearbox_files[b].string());
          face_gear_run_options(d, s.duration_s, s.fs_hz);
        } catch (const diag::InputError& e) {
          diag::fail(where, field,
                     std::string("at the ") + (hi ? "upper" : "lower") + " ends of its ranges on " +
                         s.gearbox_paths[b] + ": " + e.what());
        }
      }
    }
  }
}

json or_null(bool has, const json& v) { return has ? v : json(nullptr); }

// The gearbox paths of the spec, resolved; `add` reads each one into s and returns the text that
// enters the spec's hash. Sets s.gearbox_paths and s.hash.
void load_gearboxes(
    const diag::Fields& f, DatasetSpec& s,
    const std::function<std::string(const std::string&, const std::filesystem::path&)>& add) {
  s.gearbox_paths = parse_gearbox_paths(f);
  std::string hashed = s.json.dump();
  for (const std::string& p : s.gearbox_paths) hashed += '\0' + add(p, resolve(s, p));
  s.hash = fnv1a64_hex(hashed);
}

bool is_face_gear(const std::filesystem::path& path) {
  return std::filesystem::exists(path) && fg::is_face_gear_file(path);
}

// seed and recordings_per_class, every simulator's: sets s.seed, returns recordings_per_class.
int parse_seed_and_count(const diag::Fields& f, DatasetSpec& s) {
  const int seed = f.integer("seed");
  if (seed < 0) f.fail("seed", "must be >= 0");
  s.seed = static_cast<std::uint64_t>(seed);
  const int per_class = f.integer("recordings_per_class");
  if (per_class < 1) f.fail("recordings_per_class", "must be >= 1");
  return per_class;
}

// The manifest columns every simulator of this file starts with, and their values.
std::vector<std::string> common_columns() {
  return {"file", "id", "index", "class", "simulator", "gearbox"};
}
json common_row(const DatasetSpec& s, const DrawnRecording& r, const char* simulator) {
  json row = json::object();
  row["file"] = "recordings/" + r.id + ".h5";
  row["id"] = r.id;
  row["index"] = r.index;
  row["class"] = r.cls;
  row["simulator"] = simulator;
  row["gearbox"] = s.gearbox_paths[static_cast<std::size_t>(r.gearbox)];
  return row;
}

// Shaft angles at slow rotation with sporadic defects (sim/kinematic/sporadic_defects.hpp).
class KinematicDataset final : public DatasetSimulator {
 public:
  const char* name() const override { return "kinematic"; }

  void load(DatasetSpec& s) const override {
    const std::string where = s.file.string();
    for (const char* key : {"duration_s", "fs_hz", "operating_points", "noise_m_per_s2",
                            "accuracy_grade", "runout_um", "scenario"}) {
      if (s.json.contains(key)) {
        diag::fail(where, key,
                   "is not a field of a kinematic dataset (slow rotation, shaft angles: the "
                   "record's length and rig effects are in `kinematic`)");
      }
    }
    const diag::Fields f(
        s.json, where, "",
        {"simulator", "gearbox", "seed", "recordings_per_class", "classes", "kinematic"});
    load_gearboxes(f, s, [&](const std::string& p, const std::filesystem::path& path) {
      if (is_face_gear(path))
        f.fail("gearbox", "'" + p + "' is a face-gear pair: no kinematic model");
      s.gearboxes.push_back(diag::load_gearbox(path));
      const diag::Gearbox& gb = s.gearboxes.back();
      if (!gb.defects().empty()) {
        f.fail("gearbox", "'" + p +
                              "' has defects[]: a kinematic dataset places its classes' "
                              "defects on a gearbox without any");
      }
      if (gb.power_path().empty()) {
        f.fail("gearbox", "'" + p + "': input and output are one shaft, no mesh carries a defect");
      }
      return gb.description_json();
    });
    const int per_class = parse_seed_and_count(f, s);
    if (f.has("kinematic")) {
      const diag::Fields k(
          f.raw("kinematic"), where, "kinematic",
          {"step_deg", "revolutions", "runout_deg", "mesh_te_deg", "noise_deg", "encoder_counts"});
      KinematicSettings& ks = s.kinematic;
      if (k.has("step_deg")) {
        ks.step_deg = k.positive("step_deg");
        if (ks.step_deg > 5.7) k.fail("step_deg", "must be <= 5.7 deg (0.1 rad)");
      }
      if (k.has("revolutions")) {
        ks.revolutions = k.positive("revolutions");
        if (ks.revolutions > 1e6) k.fail("revolutions", "must be <= 1e6");
      }
      if (k.has("runout_deg")) ks.runout_deg = parse_range(k, "runout_deg", 0, 10, false);
      if (k.has("mesh_te_deg")) ks.mesh_te_deg = parse_range(k, "mesh_te_deg", 0, 10, false);
      if (k.has("noise_deg")) ks.noise_deg = parse_range(k, "noise_deg", 0, 10, false);
      if (k.has("encoder_counts")) {
        const int counts = k.integer("encoder_counts");
        if (counts != 0 && (counts < 16 || counts > (1 << 30))) {
          k.fail("encoder_counts", "must be 0 (no quantisation) or in [16, 2^30]");
        }
        ks.encoder_counts = counts;
      }
    }
    parse_classes(f, per_class, {"defects"}, s, [&](const diag::Fields& cf, DatasetClass& cls) {
      if (!cf.has("defects")) return;
      if (!cf.raw("defects").is_array()) cf.fail("defects", "must be an array");
      for (std::size_t i = 0; i < cf.raw("defects").size(); ++i) {
        cls.defects.push_back(
            parse_defect(cf.raw("defects")[i], where, cf.sub(indexed("defects", i))));
      }
    });
    check_kinematic(s);
  }

  void draw(const DatasetSpec& s, const DatasetClass& cls, DrawStream& rng,
            DrawnRecording& r) const override {
    r.gearbox = static_cast<int>(rng.pick(s.gearboxes.size()));
    const diag::Gearbox& gb = s.gearboxes[static_cast<std::size_t>(r.gearbox)];
    r.runout_deg = rng.draw(s.kinematic.runout_deg);
    r.mesh_te_deg = rng.draw(s.kinematic.mesh_te_deg);
    r.kin_noise_deg = rng.draw(s.kinematic.noise_deg);
    const double u_total = gb.total_ratio();
    double max_out_deg = 0;  // the class's largest defect at the output
    for (const KinematicDefect& d : cls.defects) {
      for (int g : candidates(d, gb)) {
        max_out_deg =
            std::max(max_out_deg, d.size_deg.hi / (d.size_at_output ? 1.0 : gb.ratio_to_output(g)));
      }
    }
    // Two defects on one shaft whose events fall within this input angle of each other are one
    // event by construction (the attribution loop's rule, validation/src/attribution_loop.cpp):
    // the later one moves on by it.
    const double clash_deg = std::max(10.0, 8.0 * max_out_deg * u_total);
    double smallest_pulse = INFINITY;
    json desc = json::parse(gb.description_json());
    desc["defects"] = json::array();
    for (const KinematicDefect& kd : cls.defects) {
      const std::vector<int> gears = candidates(kd, gb);
      const int g = gears[rng.pick(gears.size())];
      DrawnDefect d;
      d.type = kd.type;
      d.gear = gb.gears()[g].name;
      d.shaft = gb.gears()[g].shaft;
      const double u_i = gb.ratio_to_output(g);
      const double size = rng.draw(kd.size_deg);
      d.size_gear_deg = kd.size_at_output ? size * u_i : size;
      d.size_output_deg = d.size_gear_deg / u_i;
      d.phase_deg = kd.any_phase ? rng.draw(Range{0, 359.9999}) : rng.draw(kd.phase_deg);
      d.period_input_rev = gb.recurrence_period_input_rev(g);
      const double period_deg = 360.0 * d.period_input_rev;
      for (int tries = 0; tries < 16; ++tries) {
        const bool clash =
            std::any_of(r.defects.begin(), r.defects.end(), [&](const DrawnDefect& o) {
              if (o.shaft != d.shaft) return false;
              double x = std::fmod(
                  std::abs(o.phase_deg * o.period_input_rev - d.phase_deg * d.period_input_rev),
                  period_deg);
              return std::min(x, period_deg - x) < clash_deg;
            });
        if (!clash) break;
        d.phase_deg =
            std::round(std::fmod(d.phase_deg + clash_deg / d.period_input_rev, 360.0) * 1e4) / 1e4;
        if (d.phase_deg >= 360.0) d.phase_deg = 0.0;
      }
      d.first_event_input_deg = d.phase_deg * d.period_input_rev;
      smallest_pulse =
          std::min(smallest_pulse, pulse_input_rad(gb, g, deg_to_rad(d.size_gear_deg)));
      desc["defects"].push_back({{"gear", d.gear},
                                 {"type", d.type},
                                 {"size_deg", d.size_gear_deg},
                                 {"phase_deg", d.phase_deg}});
      r.defects.push_back(d);
    }
    r.seed = rng.next() % 1000000000ULL;
    r.step_rad = s.kinematic.step_deg > 0
                     ? deg_to_rad(s.kinematic.step_deg)
                     : std::min(kDefaultStepRad, smallest_pulse / kStepsPerPulse);
    r.revolutions = kinematic_revolutions(s, gb);
    r.model = desc;
  }

  std::vector<std::string> manifest_columns(const DatasetSpec& s) const override {
    std::vector<std::string> cols = common_columns();
    for (const char* c : {"seed", "step_rad", "revolutions", "runout_deg", "mesh_te_deg",
                          "noise_deg", "encoder_counts", "defects"}) {
      cols.push_back(c);
    }
    for (std::size_t i = 1; i <= s.max_faults; ++i) {
      for (const char* field : {"type", "gear", "shaft", "size_gear_deg", "size_output_deg",
                                "phase_deg", "period_input_rev", "first_event_input_deg"}) {
        cols.push_back("defect" + std::to_string(i) + "_" + field);
      }
    }
    return cols;
  }

  json manifest_row(const DatasetSpec& s, const DrawnRecording& r) const override {
    json row = common_row(s, r, name());
    row["seed"] = r.seed;
    row["step_rad"] = r.step_rad;
    row["revolutions"] = r.revolutions;
    row["runout_deg"] = r.runout_deg;
    row["mesh_te_deg"] = r.mesh_te_deg;
    row["noise_deg"] = r.kin_noise_deg;
    row["encoder_counts"] = s.kinematic.encoder_counts;
    row["defects"] = r.defects.size();
    for (std::size_t i = 0; i < s.max_faults; ++i) {
      const std::string p = "defect" + std::to_string(i + 1) + "_";
      const bool has = i < r.defects.size();
      const DrawnDefect d = has ? r.defects[i] : DrawnDefect{};
      row[p + "type"] = or_null(has, d.type);
      row[p + "gear"] = or_null(has, d.gear);
      row[p + "shaft"] = or_null(has, d.shaft);
      row[p + "size_gear_deg"] = or_null(has, d.size_gear_deg);
      row[p + "size_output_deg"] = or_null(has, d.size_output_deg);
      row[p + "phase_deg"] = or_null(has, d.phase_deg);
      row[p + "period_input_rev"] = or_null(has, d.period_input_rev);
      row[p + "first_event_input_deg"] = or_null(has, d.first_event_input_deg);
    }
    return row;
  }

  diag::Recording simulate(const DatasetSpec& s, const DrawnRecording& r,
                           std::vector<std::string>& /*warnings*/) const override {
    const diag::Gearbox gb = diag::parse_gearbox(r.model, r.id + ": gearbox");
    sim::KinematicOptions o;
    o.step_rad = r.step_rad;
    o.revolutions = r.revolutions;
    o.runout_output_rad = deg_to_rad(r.runout_deg);
    o.mesh_te_output_rad = deg_to_rad(r.mesh_te_deg);
    o.noise_output_rad = deg_to_rad(r.kin_noise_deg);
    o.encoder_counts_per_rev = s.kinematic.encoder_counts;
    o.seed = r.seed;
    return sim::to_recording(gb, sim::simulate_kinematic(gb, o));
  }

  const json& model(const DrawnRecording& r) const override { return r.model; }
};

// The face-gear pair (sim/facegear/face_gear.hpp), as `geardiag simulate` runs it.
class FaceGearDataset final : public DatasetSimulator {
 public:
  const char* name() const override { return "face_gear"; }

  void load(DatasetSpec& s) const override {
    const std::string where = s.file.string();
    const diag::Fields f(s.json, where, "",
                         {"simulator", "gearbox", "seed", "recordings_per_class", "classes",
                          "duration_s", "fs_hz", "operating_points", "face_gear"});
    load_gearboxes(f, s, [&](const std::string& p, const std::filesystem::path& path) {
      if (!is_face_gear(path)) {
        f.fail("gearbox", "'" + p +
                              "' is not a face-gear description (a face-gear dataset takes "
                              "only face-gear pairs)");
      }
      const json desc = diag::load_json_file(path);
      fg::parse_description(desc, path.string());
      s.gearbox_json.push_back(desc);
      s.gearbox_files.push_back(path);
      return desc.dump();
    });
    const int per_class = parse_seed_and_count(f, s);
    s.duration_s = f.positive("duration_s");
    if (s.duration_s > 600) f.fail("duration_s", "must be <= 600 s for a face-gear pair");
    s.fs_hz = f.positive("fs_hz");
    if (s.fs_hz > 1e6) f.fail("fs_hz", "must be <= 1e6 Hz");
    FaceGearRanges top;
    parse_face_gear_fields(f, top);
    parse_classes(f, per_class, {"operating_points", "face_gear"}, s,
                  [&](const diag::Fields& cf, DatasetClass& cls) {
                    cls.face_gear = top;
                    parse_face_gear_fields(cf, cls.face_gear);
                  });
    check_face_gear(s);
  }

  void draw(const DatasetSpec& s, const DatasetClass& cls, DrawStream& rng,
            DrawnRecording& r) const override {
    r.gearbox = static_cast<int>(rng.pick(s.gearbox_json.size()));
    const json& desc = s.gearbox_json[static_cast<std::size_t>(r.gearbox)];
    const FaceGearRanges& fr = cls.face_gear;
    r.speed_rpm = rng.draw(fr.speed_rpm);
    r.torque_nm = rng.draw(fr.torque_nm);
    const double backlash = rng.draw(fr.backlash_um);
    r.backlash_um = fr.has_backlash ? backlash : desc["face_gear_pair"].value("backlash_um", 50.0);
    r.stiffness_scale = rng.draw(fr.stiffness_scale);
    r.static_te_scale = rng.draw(fr.static_te_scale);
    r.input_amplitude = rng.draw(fr.input_amplitude);
    r.input_frequency_hz = rng.draw(fr.input_frequency_hz);
    r.load_amplitude = rng.draw(fr.load_amplitude);
    r.load_frequency_hz = rng.draw(fr.load_frequency_hz);
    r.model = face_gear_model(desc, r.speed_rpm, r.torque_nm, fr, r.backlash_um, r.stiffness_scale,
                              r.input_amplitude, r.input_frequency_hz, r.load_amplitude,
                              r.load_frequency_hz);
  }

  std::vector<std::string> manifest_columns(const DatasetSpec& /*s*/) const override {
    std::vector<std::string> cols = common_columns();
    for (const char* c :
         {"speed_rpm", "torque_nm", "backlash_um", "stiffness_scale", "static_te_scale",
          "input_amplitude", "input_frequency_hz", "load_amplitude", "load_frequency_hz",
          "duration_s", "fs_hz", "mesh_frequency_hz", "natural_frequency_hz", "dlf", "impact",
          "period", "dte_peak_to_peak_urad"}) {
      cols.push_back(c);
    }
    return cols;
  }

  json manifest_row(const DatasetSpec& s, const DrawnRecording& r) const override {
    json row = common_row(s, r, name());
    row["speed_rpm"] = r.speed_rpm;
    row["torque_nm"] = r.torque_nm;
    row["backlash_um"] = r.backlash_um;
    row["stiffness_scale"] = r.stiffness_scale;
    row["static_te_scale"] = r.static_te_scale;
    row["input_amplitude"] = r.input_amplitude;
    row["input_frequency_hz"] = r.input_frequency_hz;
    row["load_amplitude"] = r.load_amplitude;
    row["load_frequency_hz"] = r.load_frequency_hz;
    row["duration_s"] = s.duration_s;
    row["fs_hz"] = s.fs_hz;
    for (const char* c : {"mesh_frequency_hz", "natural_frequency_hz", "dlf", "impact", "period",
                          "dte_peak_to_peak_urad"}) {
      row[c] = nullptr;  // the outcome: add_outcomes
    }
    return row;
  }

  diag::Recording simulate(const DatasetSpec& s, const DrawnRecording& r,
                           std::vector<std::string>& /*warnings*/) const override {
    fg::Description d =
        fg::parse_description(r.model, s.gearbox_files[static_cast<std::size_t>(r.gearbox)]);
    if (r.static_te_scale != 1.0) {
      fg::apply_scenario(d, {{"static_te_scale", r.static_te_scale}}, r.id);
    }
    FaceGearSimulateArgs a;
    a.duration_s = s.duration_s;
    a.fs_hz = s.fs_hz;
    return face_gear_recording(d, r.model.dump(2), a);
  }

  const json& model(const DrawnRecording& r) const override { return r.model; }

  // DLF, impact and period classes, DTE peak to peak: read back from the simulation's truth.
  bool has_outcomes() const override { return true; }
  void add_outcomes(const json& truth, json& row) const override {
    for (const char* c : {"mesh_frequency_hz", "natural_frequency_hz", "dlf", "impact", "period"}) {
      if (truth.contains(c)) row[c] = truth[c];
    }
    if (truth.contains("dte_peak_to_peak_rad")) {
      row["dte_peak_to_peak_urad"] = truth["dte_peak_to_peak_rad"].get<double>() * 1e6;
    }
  }
};

}  // namespace

const DatasetSimulator& kinematic_dataset_simulator() {
  static const KinematicDataset instance;
  return instance;
}

const DatasetSimulator& face_gear_dataset_simulator() {
  static const FaceGearDataset instance;
  return instance;
}

const DatasetSimulator* find_dataset_simulator(std::string_view name) {
  static const std::array<const DatasetSimulator*, 3> table = {
      &dynamic_dataset_simulator(), &kinematic_dataset_simulator(), &face_gear_dataset_simulator()};
  for (const DatasetSimulator* d : table) {
    if (name == d->name()) return d;
  }
  return nullptr;
}

const DatasetSimulator& simulator_of(const DatasetSpec& s) {
  const DatasetSimulator* d = find_dataset_simulator(s.simulator);
  if (!d) throw std::logic_error("dataset simulator '" + s.simulator + "' is not in the table");
  return *d;
}

std::string dataset_simulator(const nlohmann::json& spec, const std::filesystem::path& file) {
  const std::string dynamic = dynamic_dataset_simulator().name();
  if (!spec.is_object()) return dynamic;  // the dynamic parser names the error
  if (spec.contains("simulator")) {
    const json& v = spec["simulator"];
    if (!v.is_string() || !find_dataset_simulator(v.get<std::string>())) {
      diag::fail(file.string(), "simulator", "must be \"dynamic\", \"kinematic\" or \"face_gear\"");
    }
    return v.get<std::string>();
  }
  const json* g = spec.contains("gearbox") ? &spec["gearbox"] : nullptr;
  if (g && g->is_array() && !g->empty()) g = &(*g)[0];
  if (!g || !g->is_string()) return dynamic;
  std::filesystem::path p = g->get<std::string>();
  if (p.is_relative()) p = file.parent_path() / p;
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec) && fg::is_face_gear_file(p)
             ? face_gear_dataset_simulator().name()
             : dynamic;
}

}  // namespace geardiag
