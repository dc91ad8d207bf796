#include "sim/dynamics/sweep.hpp"

#include <algorithm>
#include <cmath>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/channels.hpp"
#include "diag/io/json_fields.hpp"
#include "diag/util/number_format.hpp"

namespace sim {

void SweepOptions::validate() const {
  const std::string where = "sweep";
  if (!(from_rpm > 0.0))
    throw diag::InputError(diag::format_error(where, "from_rpm", "must be > 0"));
  if (!(to_rpm > from_rpm)) {
    throw diag::InputError(diag::format_error(where, "to_rpm", "must be > from_rpm"));
  }
  if (to_rpm > diag::kMaxSpeedRpm) {
    throw diag::InputError(diag::format_error(
        where, "to_rpm", "must be <= " + diag::format_significant(diag::kMaxSpeedRpm, 6) + " rpm"));
  }
  if (steps < 2 || steps > kMaxSweepSteps) {
    throw diag::InputError(diag::format_error(where, "steps",
                                              "must be in [2, " + std::to_string(kMaxSweepSteps) +
                                                  "] (got " + std::to_string(steps) + ")"));
  }
  if (!(dwell_s >= 0.0) || !std::isfinite(dwell_s))
    throw diag::InputError(diag::format_error(where, "dwell_s", "must be >= 0"));
  if (!(fs_hz >= 0.0) || !std::isfinite(fs_hz))
    throw diag::InputError(diag::format_error(where, "fs_hz", "must be >= 0"));
}

namespace {

void cut(const DynamicResult& r, const std::vector<std::string>& channels, double rpm_start,
         double rpm_end, int steps, double z_first, double ratio_first,
         std::vector<SweepPoint>& points) {
  const std::size_t n = r.channels.front().samples.size();
  std::vector<const Channel*> contacts;
  for (const Channel& c : r.channels) {
    if (c.name.size() > 8 && c.name.compare(c.name.size() - 8, 8, "_contact") == 0)
      contacts.push_back(&c);
  }
  for (int w = 0; w < steps; ++w) {
    const std::size_t i0 = n * w / steps, i1 = n * (w + 1) / steps;
    SweepPoint p;
    p.rpm = rpm_start + (rpm_end - rpm_start) * (w + 0.5) / steps;
    p.mesh_frequency_hz = z_first * ratio_first * p.rpm / 60.0;
    for (const std::string& name : channels) {
      const Channel* c = r.find(name);
      double mean = 0.0;
      for (std::size_t i = i0; i < i1; ++i) mean += c->samples[i];
      mean /= static_cast<double>(i1 - i0);
      double peak = 0.0, ss = 0.0;
      for (std::size_t i = i0; i < i1; ++i) {
        const double d = c->samples[i] - mean;
        peak = std::max(peak, std::abs(d));
        ss += d * d;
      }
      p.peak.push_back(peak);
      p.rms.push_back(std::sqrt(ss / static_cast<double>(i1 - i0)));
    }
    std::size_t lost = 0;
    for (std::size_t i = i0; i < i1; ++i) {
      for (const Channel* c : contacts) {
        if (c->samples[i] != 1.0) {
          ++lost;
          break;
        }
      }
    }
    p.contact_loss_fraction = static_cast<double>(lost) / static_cast<double>(i1 - i0);
    points.push_back(p);
  }
}

}  // namespace

SweepResult run_sweep(const diag::Gearbox& gb, const DynamicsOptions& dynamics,
                      const RunOptions& run, const SweepOptions& sweep) {
  sweep.validate();
  SweepResult result;
  GearboxModel probe(gb, dynamics);
  result.natural_frequencies_hz = probe.natural_frequencies_hz();
  const diag::Mesh& m0 = gb.meshes().front();
  const double z0 = gb.gears()[m0.driver].spec.teeth;
  const double r0 = probe.gear_speed_ratio(m0.driver);
  for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
    const double f = probe.mesh_torsional_frequency_hz(static_cast<int>(j));
    result.mesh_torsional_frequency_hz.push_back(f);
    result.resonance_rpm.push_back(f / (z0 * r0) * 60.0);
  }
  RunOptions r = run;
  r.fs_hz = sweep.fs_hz > 0 ? sweep.fs_hz : 8.0 * z0 * r0 * sweep.to_rpm / 60.0;
  r.mesh_channels = true;
  const double dwell =
      sweep.dwell_s > 0 ? sweep.dwell_s : std::max(0.01, 200.0 / (z0 * r0 * sweep.from_rpm / 60.0));
  r.duration_s = dwell * sweep.steps;
  r.settle_s = -1.0;
  result.channels = sweep.channels;
  if (result.channels.empty()) {
    for (std::size_t j = 0; j < gb.meshes().size(); ++j) {
      result.channels.push_back(diag::mesh_name(gb, static_cast<int>(j)) + "_force");
    }
    const std::string b = bearing_location(gb.shafts()[gb.shaft_of_gear(m0.driver)].name, 1) + "_";
    result.channels.push_back(b + "along_loa");
    result.channels.push_back(b + "normal_loa");
  }
  auto run_one = [&](double a, double b, std::vector<SweepPoint>& out) {
    DynamicsOptions d = dynamics;
    d.speed = SpeedProfile::ramp(a, b, 0.0, r.duration_s);
    RunOptions rr = r;
    // Settle at the starting speed first (0.05 s: tens of time constants of the mesh and bearing
    // modes); the ramp begins when the recording does.
    const double settle = 0.05;
    d.speed.start_s = settle;
    rr.settle_s = settle;
    const DynamicResult res = simulate_dynamic(gb, d, rr);
    for (const std::string& name : result.channels) {
      if (!res.find(name)) {
        std::string list;
        for (const Channel& c : res.channels) list += (list.empty() ? "" : ", ") + c.name;
        throw diag::InputError("sweep: channel '" + name + "' does not exist (channels: " + list +
                               ")");
      }
    }
    cut(res, result.channels, a, b, sweep.steps, z0, r0, out);
  };
  run_one(sweep.from_rpm, sweep.to_rpm, result.up);
  if (sweep.down) run_one(sweep.to_rpm, sweep.from_rpm, result.down);
  return result;
}

HalfPower half_power_damping(const std::vector<double>& f, const std::vector<double>& a) {
  const std::string where = "half_power_damping";
  if (f.size() != a.size() || f.size() < 3) {
    throw diag::InputError(diag::format_error(
        where, "frequency_hz", "needs as many amplitudes as frequencies, at least 3"));
  }
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!std::isfinite(f[i]) || (i > 0 && !(f[i] > f[i - 1]))) {
      throw diag::InputError(diag::format_error(where, "frequency_hz", "must increase strictly"));
    }
    if (!(a[i] >= 0.0) || !std::isfinite(a[i])) {
      throw diag::InputError(diag::format_error(where, "amplitude", "must be finite and >= 0"));
    }
  }
  const std::size_t p = static_cast<std::size_t>(std::max_element(a.begin(), a.end()) - a.begin());
  const double level = a[p] / std::sqrt(2.0);
  // Crossing between samples i and i + step (the first below the level going outwards from p).
  const long n = static_cast<long>(f.size());
  auto crossing = [&](long step, const char* side) {
    for (long i = static_cast<long>(p); i + step >= 0 && i + step < n; i += step) {
      const long j = i + step;
      if (a[j] <= level) return f[i] + (a[i] - level) / (a[i] - a[j]) * (f[j] - f[i]);
    }
    throw diag::InputError(diag::format_error(
        where, "amplitude",
        std::string("the response does not fall to 1/sqrt(2) of its peak on the ") + side +
            " side of the peak within the data: widen the band"));
  };
  HalfPower h;
  h.peak_hz = f[p];
  h.f1_hz = crossing(-1, "low");
  h.f2_hz = crossing(1, "high");
  h.damping_ratio = (h.f2_hz - h.f1_hz) / (2.0 * h.peak_hz);
  return h;
}

nlohmann::json SweepResult::to_json() const {
  nlohmann::json j;
  j["channels"] = channels;
  j["natural_frequencies_hz"] = natural_frequencies_hz;
  j["mesh_torsional_frequency_hz"] = mesh_torsional_frequency_hz;
  j["resonance_rpm"] = resonance_rpm;
  auto points = [&](const std::vector<SweepPoint>& ps) {
    nlohmann::json arr = nlohmann::json::array();
    for (const SweepPoint& p : ps) {
      nlohmann::json o;
      o["rpm"] = p.rpm;
      o["mesh_frequency_hz"] = p.mesh_frequency_hz;
      o["contact_loss_fraction"] = p.contact_loss_fraction;
      for (std::size_t c = 0; c < channels.size(); ++c) {
        o[channels[c]] = {{"peak", p.peak[c]}, {"rms", p.rms[c]}};
      }
      arr.push_back(o);
    }
    return arr;
  };
  j["up"] = points(up);
  j["down"] = points(down);
  return j;
}

}  // namespace sim
