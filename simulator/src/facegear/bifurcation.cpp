#include "sim/facegear/bifurcation.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iomanip>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>

#include "diag/error.hpp"
#include "diag/util/parallel_for.hpp"

namespace sim::facegear {

void BifurcationOptions::validate() const {
  if (!(from_rpm > 0) || !std::isfinite(from_rpm) || !(to_rpm > from_rpm) || to_rpm > 1e5) {
    throw diag::InputError("--from-rpm/--to-rpm: need 0 < from < to <= 1e5 rpm");
  }
  if (steps < 2 || steps > 10000) throw diag::InputError("--steps: must be in [2, 10000]");
  if (transient_periods < 0 || transient_periods > 100000) {
    throw diag::InputError("--transient: must be in [0, 100000] mesh periods");
  }
  if (record_periods < 18 || record_periods > 100000) {
    throw diag::InputError("--periods: must be in [18, 100000] mesh periods");
  }
  if (threads < 0) throw diag::InputError("--threads: must be >= 0");
}

Bifurcation bifurcation(const FaceGearPair& pair, const Operating& op,
                        const BifurcationOptions& opt,
                        const std::function<void(int, int)>& progress) {
  opt.validate();
  Bifurcation out;
  out.speeds.resize(static_cast<std::size_t>(opt.steps));
  out.natural_frequency_hz = pair.natural_frequency_hz(op.torque_nm);
  for (int i = 0; i < opt.steps; ++i) {
    out.speeds[i].rpm = opt.from_rpm + (opt.to_rpm - opt.from_rpm) * i / (opt.steps - 1);
  }
  std::atomic<int> done{0};
  std::mutex progress_mutex;
  out.threads = diag::parallel_threads(out.speeds.size(), opt.threads);
  diag::parallel_for(out.speeds.size(), opt.threads, [&](std::size_t i) {
    BifurcationPoint& p = out.speeds[i];
    Operating o = op;
    o.speed_rpm = p.rpm;
    const Model model(pair, o);
    RunOptions ro;
    ro.integrator = opt.integrator;
    // The adaptive integrator chooses its own steps; the grid only samples the Poincare points,
    // the DTE range and the GMF / 2 and GMF sums (32 points per period).
    ro.steps_per_period =
        opt.integrator == Integrator::kAdaptive ? 32 : rk4_steps_per_period(model);
    ro.transient_periods = opt.transient_periods;
    ro.record_periods = opt.record_periods;
    ro.keep_trace = false;
    const Trace tr = run(model, ro);
    p.points = tr.poincare;
    p.period_class = classify_period(tr);
    p.impact = classify_impacts(tr.contact_steps);
    p.dlf = tr.max_abs_mesh_torque / model.static_torque();
    p.mean_mesh_torque = tr.mean_mesh_torque;
    const long total = tr.contact_steps[0] + tr.contact_steps[1] + tr.contact_steps[2];
    p.free_share = static_cast<double>(tr.contact_steps[1]) / static_cast<double>(total);
    p.half_gmf_ratio = tr.half_gmf_ratio;
    const int d = ++done;
    if (progress) {
      const std::lock_guard<std::mutex> lock(progress_mutex);
      progress(d, opt.steps);
    }
  });
  return out;
}

nlohmann::json Bifurcation::to_json() const {
  nlohmann::json j;
  nlohmann::json rpm = nlohmann::json::array(), pts = nlohmann::json::array(),
                 cls = nlohmann::json::array(), imp = nlohmann::json::array(),
                 dlf = nlohmann::json::array(), free = nlohmann::json::array(),
                 half = nlohmann::json::array(), torque = nlohmann::json::array();
  for (const BifurcationPoint& p : speeds) {
    rpm.push_back(p.rpm);
    pts.push_back(p.points);
    cls.push_back(p.period_class);
    imp.push_back(to_string(p.impact));
    dlf.push_back(p.dlf);
    free.push_back(p.free_share);
    half.push_back(p.half_gmf_ratio);
    torque.push_back(p.mean_mesh_torque);
  }
  j["speeds_rpm"] = rpm;
  j["points"] = pts;
  j["points_unit"] = "rad (DTE, face-gear angle, once per mesh period)";
  j["class"] = cls;
  j["impact"] = imp;
  j["dlf"] = dlf;
  j["free_flight_share"] = free;
  j["half_gmf_ratio"] = half;
  j["mean_mesh_torque_nm"] = torque;
  j["natural_frequency_hz"] = natural_frequency_hz;
  return j;
}

std::string Bifurcation::to_svg(const std::string& title) const {
  const double w = 900, h = 480, left = 80, right = 20, top = 40, bottom = 50;
  double lo = 1e300, hi = -1e300;
  for (const auto& p : speeds) {
    for (double v : p.points) {
      lo = std::min(lo, v * 1e6);
      hi = std::max(hi, v * 1e6);
    }
  }
  if (!(hi > lo)) {
    lo -= 1;
    hi += 1;
  }
  const double pad = 0.05 * (hi - lo);
  lo -= pad;
  hi += pad;
  const double r0 = speeds.front().rpm, r1 = speeds.back().rpm;
  auto sx = [&](double r) { return left + (r - r0) / (r1 - r0) * (w - left - right); };
  auto sy = [&](double v) { return top + (hi - v) / (hi - lo) * (h - top - bottom); };
  std::ostringstream o;
  o << std::fixed << std::setprecision(1);
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << h
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" "
       "fill=\"white\"/>\n<text x=\""
    << w / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">" << title << "</text>\n";
  o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << w - left - right
    << "\" height=\"" << h - top - bottom << "\" fill=\"none\" stroke=\"black\"/>\n";
  for (int i = 0; i <= 5; ++i) {
    const double r = r0 + (r1 - r0) * i / 5, v = lo + (hi - lo) * i / 5;
    o << "<text x=\"" << sx(r) << "\" y=\"" << h - bottom + 18 << "\" text-anchor=\"middle\">"
      << std::setprecision(0) << r << "</text>\n<text x=\"" << left - 6 << "\" y=\"" << sy(v) + 4
      << "\" text-anchor=\"end\">" << std::setprecision(1) << v << "</text>\n";
  }
  o << "<text x=\"" << w / 2 << "\" y=\"" << h - 10
    << "\" text-anchor=\"middle\">input speed [rpm]</text>\n<text transform=\"translate(18,"
    << h / 2 << ") rotate(-90)\" text-anchor=\"middle\">DTE once per mesh period [urad]</text>\n";
  const char* colours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728"};
  const char* names[] = {"period-1", "period-2", "period-n", "chaos"};
  for (int c = 0; c < 4; ++c) {
    o << "<path stroke=\"" << colours[c]
      << "\" stroke-width=\"2\" stroke-linecap=\"round\" fill=\"none\" d=\"";
    for (const auto& p : speeds) {
      if (p.period_class != names[c]) continue;
      for (double v : p.points) o << 'M' << sx(p.rpm) << ' ' << sy(v * 1e6) << "h0";
    }
    o << "\"/>\n<text x=\"" << left + 10 + 90 * c << "\" y=\"" << top + 16 << "\" fill=\""
      << colours[c] << "\">" << names[c] << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace sim::facegear
