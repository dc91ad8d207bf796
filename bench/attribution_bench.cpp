// Attribution speed: a 10-million-sample angle record (the seed-003 gearbox with two defects,
// runout, mesh TE, noise and 16-bit encoders) through detect::attribute_defects on one core.
#include <benchmark/benchmark.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "detect/attribution/period_matcher.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/units.hpp"
#include "sim/kinematic/sporadic_defects.hpp"

namespace {

const diag::Gearbox& gearbox() {
  // The seed-003 gearbox of testdata/, with two defects added.
  static const diag::Gearbox gb = [] {
    std::ifstream in(GEARDIAG_TESTDATA_DIR "/gearbox/three_shaft.json");
    nlohmann::json j = nlohmann::json::parse(in);
    j["defects"] = nlohmann::json::parse(R"([{"gear": "z2", "size_deg": 0.4, "phase_deg": 10.0},
                                             {"gear": "z4", "size_deg": 0.3, "phase_deg": 95.0}])");
    return diag::parse_gearbox(j, "bench");
  }();
  return gb;
}

const sim::KinematicResult& record(std::int64_t samples) {
  static std::map<std::int64_t, sim::KinematicResult> cache;
  auto it = cache.find(samples);
  if (it != cache.end()) return it->second;
  sim::KinematicOptions o;
  o.revolutions = 24.0;
  o.step_rad = o.revolutions * diag::units::kTwoPi / static_cast<double>(samples - 1);
  o.runout_output_rad = diag::units::deg_to_rad(0.05);
  o.mesh_te_output_rad = diag::units::deg_to_rad(0.005);
  o.noise_output_rad = diag::units::deg_to_rad(0.002);
  o.encoder_counts_per_rev = 1 << 16;
  return cache.emplace(samples, sim::simulate_kinematic(gearbox(), o)).first->second;
}

void BM_AttributeDefects(benchmark::State& state) {
  const auto& r = record(state.range(0));
  std::size_t findings = 0;
  for (auto _ : state) {
    const auto a = detect::attribute_defects(r.input_angle_rad, r.output_angle_rad, gearbox(), {});
    findings = a.findings.size();
    benchmark::DoNotOptimize(findings);
  }
  if (findings != 2) state.SkipWithError("wrong attribution in the benchmark record");
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_AttributeDefects)->Arg(1'000'000)->Arg(10'000'000)->Unit(benchmark::kMillisecond);

void BM_SimulateKinematic(benchmark::State& state) {
  sim::KinematicOptions o;
  o.revolutions = 24.0;
  o.step_rad = o.revolutions * diag::units::kTwoPi / static_cast<double>(state.range(0) - 1);
  for (auto _ : state) {
    auto r = sim::simulate_kinematic(gearbox(), o);
    benchmark::DoNotOptimize(r.output_angle_rad.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_SimulateKinematic)->Arg(1'000'000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
