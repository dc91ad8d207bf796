// Dynamics speed on one core.
//  BM_Rk4Pair: the seed-000 6-DOF spur pair (testdata/gearbox/seed000_pair.json, 3000 rpm,
//    2000 N m, Drozdov friction, back flank, speed-controlled motor) stepped by sim::Rk4 at the
//    step sim::simulate_dynamic would choose for a 50 kHz output (items_per_second = RK4 steps/s;
//    one step is four evaluations of the right-hand side).
//  BM_SimulateThreeShaft: one second of the two-stage gearbox (testdata/gearbox/three_shaft.json)
//    at 50 kHz output through sim::simulate_dynamic with default options (automatic settling
//    time, every channel).
//
// `bench_dynamics --export FILE [--span S]` does not benchmark: it writes the pair model's
// parameters, tables, a few right-hand-side evaluations and an RK4 trajectory of the mesh force
// over S seconds (default 0.01) as JSON for bench/peer_dynamics.py, which integrates the same
// model with scipy's solve_ivp. The parameters are recomputed here with the formulas of
// simulator/src/dynamics/gearbox_model.cpp (the model keeps them private); the right-hand-side
// samples let the Python side prove it has the same model.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "diag/gearbox/gearbox.hpp"
#include "diag/geometry/gear.hpp"
#include "sim/dynamics/gearbox_model.hpp"
#include "sim/dynamics/rk4.hpp"
#include "sim/dynamics/simulate.hpp"
#include "sim/mesh/friction.hpp"
#include "sim/mesh/mesh_stiffness.hpp"

namespace {

constexpr double kPi = std::numbers::pi;

const diag::Gearbox& pair_gearbox() {
  static const diag::Gearbox gb =
      diag::load_gearbox(GEARDIAG_TESTDATA_DIR "/gearbox/seed000_pair.json");
  return gb;
}

const diag::Gearbox& three_shaft_gearbox() {
  static const diag::Gearbox gb =
      diag::load_gearbox(GEARDIAG_TESTDATA_DIR "/gearbox/three_shaft.json");
  return gb;
}

sim::DynamicsOptions pair_options() {
  sim::DynamicsOptions o;
  o.friction.law = sim::FrictionLaw::kDrozdov;
  return o;
}

// The step simulate_dynamic chooses for a 50 kHz output (RunOptions defaults: 20 steps per period
// of the highest natural frequency, 48 per mesh period, at least 4 steps per output sample).
double auto_step(const sim::GearboxModel& model, double fs_hz) {
  const diag::Gearbox& gb = model.gearbox();
  const double f_max = model.natural_frequencies_hz().back();
  const double w_in = model.options().speed.max_rpm() * 2 * kPi / 60.0;
  double f_mesh = 0.0;
  for (const diag::Mesh& m : gb.meshes()) {
    f_mesh = std::max(f_mesh, gb.gears()[m.driver].spec.teeth * model.gear_speed_ratio(m.driver) *
                                  w_in / (2 * kPi));
  }
  const double h_needed = std::min(1.0 / (f_max * 20), 1.0 / (f_mesh * 48));
  const int d = std::max(4, static_cast<int>(std::ceil(1.0 / (fs_hz * h_needed) - 1e-9)));
  return 1.0 / (fs_hz * d);
}

void BM_Rk4Pair(benchmark::State& state) {
  const sim::GearboxModel model(pair_gearbox(), pair_options());
  const double h = auto_step(model, 50000.0);
  const std::vector<double> y0 = model.equilibrium_state();
  std::vector<double> y = y0;
  sim::Rk4 rk4(static_cast<int>(y.size()));
  const std::int64_t steps = state.range(0);
  for (auto _ : state) {
    std::copy(y0.begin(), y0.end(), y.begin());
    double t = 0.0;
    for (std::int64_t i = 0; i < steps; ++i) {
      rk4.step(model, t, h, y.data());
      t += h;
    }
    benchmark::DoNotOptimize(y.data());
  }
  if (!std::isfinite(y[0])) state.SkipWithError("the pair diverged");
  state.counters["step_us"] = h * 1e6;
  state.SetItemsProcessed(state.iterations() * steps);
}
// 100 000 steps: about 0.45 s of simulated time at the automatic step.
BENCHMARK(BM_Rk4Pair)->Arg(100'000)->Unit(benchmark::kMillisecond);

// The right-hand side alone, at states along a trajectory (evaluations per second).
void BM_DerivativesPair(benchmark::State& state) {
  const sim::GearboxModel model(pair_gearbox(), pair_options());
  const double h = auto_step(model, 50000.0);
  std::vector<double> y = model.equilibrium_state();
  sim::Rk4 rk4(static_cast<int>(y.size()));
  constexpr int kStates = 1024;
  std::vector<std::vector<double>> ys;
  std::vector<double> ts;
  double t = 0.0;
  for (int i = 0; i < kStates; ++i) {
    ys.push_back(y);
    ts.push_back(t);
    rk4.step(model, t, h, y.data());
    t += h;
  }
  std::vector<double> dydt(y.size());
  for (auto _ : state) {
    for (int i = 0; i < kStates; ++i) {
      model.derivatives(ts[i], ys[i].data(), dydt.data());
      benchmark::DoNotOptimize(dydt.data());
    }
  }
  state.SetItemsProcessed(state.iterations() * kStates);
}
BENCHMARK(BM_DerivativesPair);

void BM_SimulateThreeShaft(benchmark::State& state) {
  const diag::Gearbox& gb = three_shaft_gearbox();
  sim::RunOptions run;
  run.duration_s = 1.0;
  run.fs_hz = 50000.0;
  sim::DynamicResult r;
  for (auto _ : state) {
    r = sim::simulate_dynamic(gb, sim::DynamicsOptions{}, run);
    benchmark::DoNotOptimize(r.channels.data());
  }
  state.counters["step_us"] = r.step_s * 1e6;
  state.counters["decimation"] = r.decimation;
  state.counters["channels"] = static_cast<double>(r.channels.size());
  state.counters["settle_s"] =
      r.truth.value("integrator", nlohmann::json::object()).value("settle_s", -1.0);
  state.SetItemsProcessed(state.iterations() *
                          static_cast<std::int64_t>(run.duration_s * run.fs_hz));
}
BENCHMARK(BM_SimulateThreeShaft)->Unit(benchmark::kMillisecond)->Iterations(2);

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// ---- export for bench/peer_dynamics.py
// -----------------------------------------------------------
int export_pair_model(const std::string& path, double span_s) {
  const diag::Gearbox& gb = pair_gearbox();
  const sim::DynamicsOptions opt = pair_options();
  const sim::GearboxModel model(gb, opt);
  const sim::DynamicsOptions& o = model.options();  // defaults resolved (speed, torque)
  const diag::Mesh& mesh = gb.meshes().at(0);
  const diag::GearPair& pair = mesh.pair;
  const int n = model.dofs();
  if (n != 6 || gb.meshes().size() != 1) {
    std::cerr << "export: expected the 6-DOF single pair, got " << n << " DOFs\n";
    return 1;
  }

  // Masses per DOF (gearbox_model.cpp: gears first, then x, y of each shaft with gears).
  std::vector<double> mass(n, 0.0);
  for (int g = 0; g < 2; ++g) {
    const diag::Gear gear(gb.gears()[g].spec);
    const int x = model.shaft_x_dof(gb.shaft_of_gear(g));
    mass[g] = gear.disc_inertia_kg_m2();
    mass[x] += gear.disc_mass_kg();
    mass[x + 1] += gear.disc_mass_kg();
  }
  const int a = mesh.driver, b = mesh.driven;
  const int xa = model.shaft_x_dof(gb.shaft_of_gear(a)),
            xb = model.shaft_x_dof(gb.shaft_of_gear(b));
  const double rba = pair.driver().base_radius_m(), rbb = pair.driven().base_radius_m();
  const double k_mean = model.mean_mesh_stiffness_n_per_m(0);
  const double inv_je = rba * rba / mass[a] + rbb * rbb / mass[b];
  const double c_z = 2 * o.mesh_damping_ratio * std::sqrt(k_mean / inv_je);
  // Bearings: two per shaft.
  std::vector<double> kx(n, 0.0), ky(n, 0.0), cx(n, 0.0), cy(n, 0.0);
  for (int x : {xa, xb}) {
    kx[x] = 2 * o.bearing_stiffness_x_n_per_m;
    ky[x] = 2 * o.bearing_stiffness_y_n_per_m;
    cx[x] = 2 * o.bearing_damping_ratio * std::sqrt(kx[x] * mass[x]);
    cy[x] = 2 * o.bearing_damping_ratio * std::sqrt(ky[x] * mass[x + 1]);
  }
  // Coupling (speed mode, automatic stiffness: 1/20 of the mesh's torsional frequency).
  const int in = model.input_gear(), out = model.output_gear();
  double k_c = o.coupling_stiffness_nm_per_rad;
  if (k_c == 0.0) {
    const double w_c = std::sqrt(k_mean * inv_je) / 20.0;
    k_c = mass[in] * w_c * w_c;
  }
  const double c_c = 2 * o.coupling_damping_ratio * std::sqrt(k_c * mass[in]);
  // LOA frame.
  const double aw = pair.working_pressure_angle_rad();
  const double sigma = gb.shafts()[gb.shaft_of_gear(a)].speed_ratio >= 0 ? 1.0 : -1.0;
  // Tables: the healthy pair stiffness on MeshStiffness's own grid (grid_points over the path of
  // contact, so linear interpolation reproduces it) and mu on the friction table's grid.
  const sim::MeshStiffness stiffness(pair, o.stiffness);
  const int grid = o.stiffness.grid_points;
  std::vector<double> k_table(grid);
  for (int i = 0; i < grid; ++i) {
    const double s = pair.s_start_m() + pair.path_of_contact_m() * i / (grid - 1);
    k_table[i] = stiffness.pair_stiffness(s, 0, 0);
  }
  const double w_in = o.speed.speed_rad_per_s(0.0);
  const double ra = model.gear_speed_ratio(a);
  const sim::FrictionModel friction(o.friction, pair);
  const std::vector<double> mu = friction.tabulate(w_in * ra, o.input_torque_nm / ra / rba, 257);

  nlohmann::json j;
  j["model"] =
      "seed-000 pair, gearbox_model.cpp equations, healthy teeth, no pitch errors, no runout";
  j["dofs"] = n;
  j["mass"] = mass;
  j["driver"] = a;
  j["driven"] = b;
  j["xa"] = xa;
  j["xb"] = xb;
  j["rba"] = rba;
  j["rbb"] = rbb;
  j["ra"] = ra;
  j["rb"] = model.gear_speed_ratio(b);
  j["nx"] = std::sin(aw);
  j["ny"] = sigma * std::cos(aw);
  j["tx"] = -std::cos(aw);
  j["ty"] = sigma * std::sin(aw);
  j["za"] = pair.driver().teeth();
  j["zb"] = pair.driven().teeth();
  j["s_start"] = pair.s_start_m();
  j["s_end"] = pair.s_end_m();
  j["s_pitch"] = pair.s_pitch_m();
  j["base_pitch"] = pair.base_pitch_m();
  j["loa"] = pair.loa_length_m();
  j["k_mean"] = k_mean;
  j["c_z"] = c_z;
  j["backlash"] = model.mesh_backlash_m(0);
  j["back_flank"] = o.back_flank;
  j["k_table"] = k_table;  // on s_start + i (s_end - s_start) / (grid - 1)
  j["mu_table"] = mu;      // on s_start + i (s_end - s_start) / 256
  j["friction_law"] = sim::to_string(o.friction.law);
  j["bearing_kx"] = kx;
  j["bearing_ky"] = ky;
  j["bearing_cx"] = cx;
  j["bearing_cy"] = cy;
  j["input_gear"] = in;
  j["output_gear"] = out;
  j["coupling_k"] = k_c;
  j["coupling_c"] = c_c;
  j["load_torque"] = model.load_torque_nm();
  j["input_torque"] = model.input_torque_nm();
  j["omega_in"] = w_in;

  // Right-hand-side samples: the equilibrium and states along the RK4 trajectory, perturbed.
  const double h = auto_step(model, 50000.0);
  const std::vector<double> y0 = model.equilibrium_state();
  j["y0"] = y0;
  j["step_s"] = h;
  std::vector<double> y = y0, dydt(2 * n);
  sim::Rk4 rk4(2 * n);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g;
  nlohmann::json samples = nlohmann::json::array();
  sim::Observation obs;
  obs.meshes.resize(1);
  double t = 0.0;
  for (int i = 0; i < 400; ++i) {
    if (i % 20 == 0) {
      std::vector<double> yp = y;
      for (double& v : yp) v *= 1.0 + 0.05 * g(rng);
      model.derivatives(t, yp.data(), dydt.data(), &obs);
      samples.push_back({{"t", t}, {"y", yp}, {"dydt", dydt}, {"force", obs.meshes[0].force_n}});
    }
    rk4.step(model, t, h, y.data());
    t += h;
  }
  j["rhs_samples"] = samples;

  // RK4 trajectory over the span: mesh force at the start of every step, and the CPU time of the
  // span (best of 20 runs, without the observation) for the ratio against scipy.
  const long long steps = std::llround(span_s / h);
  std::vector<double> times, forces;
  y = y0;
  t = 0.0;
  for (long long i = 0; i <= steps; ++i) {
    model.derivatives(t, y.data(), dydt.data(), &obs);
    times.push_back(t);
    forces.push_back(obs.meshes[0].force_n);
    if (i == steps) break;
    rk4.step(model, t, h, y.data());
    t = (i + 1) * h;
  }
  double best = std::numeric_limits<double>::infinity();
  for (int rep = 0; rep < 20; ++rep) {
    y = y0;
    const double c0 = cpu_seconds();
    for (long long i = 0; i < steps; ++i) rk4.step(model, i * h, h, y.data());
    best = std::min(best, cpu_seconds() - c0);
    benchmark::DoNotOptimize(y.data());
  }
  j["trajectory"] = {{"t", times}, {"force", forces}, {"y_end", y}};
  j["span_s"] = steps * h;
  j["rk4_steps"] = steps;
  j["rk4_cpu_s"] = best;
  std::ofstream f(path);
  f << j.dump(1) << '\n';
  if (!f) {
    std::cerr << "export: cannot write " << path << '\n';
    return 1;
  }
  std::cerr << "exported the pair model to " << path << ": " << steps << " RK4 steps of " << h * 1e6
            << " us in " << best * 1e3 << " ms CPU\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--export") == 0) {
      if (i + 1 >= argc) {
        std::cerr << "usage: bench_dynamics --export FILE [--span SECONDS]\n";
        return 2;
      }
      double span = 0.01;
      for (int k = 1; k + 1 < argc; ++k) {
        if (std::strcmp(argv[k], "--span") == 0) span = std::stod(argv[k + 1]);
      }
      return export_pair_model(argv[i + 1], span);
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
