// Wear history speed (the aim: a 100-step history of one pair in seconds): the 18/36 seed pair
// (m = 3 mm, b = 20 mm, 50 N m), 100 blocks of each law with the default 101 profile points and 64
// TE angles per mesh period; plus the pieces: rack generation of one flank and one unloaded TE
// evaluation (one driver angle) of the healthy pair.
#include <benchmark/benchmark.h>

#include <memory>
#include <nlohmann/json.hpp>

#include "diag/gearbox/gearbox.hpp"
#include "diag/geometry/profile.hpp"
#include "sim/wear/wear.hpp"

namespace {

const diag::Gearbox& gearbox() {
  static const diag::Gearbox gb =
      diag::parse_gearbox(nlohmann::json::parse(R"({"shafts": [{"name": "in"}, {"name": "out"}],
   "gears": [{"name": "pinion", "shaft": "in", "teeth": 18, "module_mm": 3.0, "face_width_mm": 20},
             {"name": "wheel", "shaft": "out", "teeth": 36, "module_mm": 3.0, "face_width_mm": 20}],
   "meshes": [{"driver": "pinion", "driven": "wheel"}],
   "input": {"shaft": "in", "speed_rpm": 1000.0, "torque_nm": 50.0}})"),
                          "bench");
  return gb;
}

void BM_WearHistory100Steps(benchmark::State& state) {
  sim::WearOptions o;
  o.law = state.range(0) == 0 ? sim::WearLaw::kArchard : sim::WearLaw::kSeed004;
  o.cycles = 1e7;
  o.steps = 100;
  o.depth_limit_m = 1e-3;  // run all 100 steps
  for (auto _ : state) benchmark::DoNotOptimize(sim::simulate_wear(gearbox(), 0, o));
  state.SetLabel(state.range(0) == 0 ? "archard" : "seed004");
}
BENCHMARK(BM_WearHistory100Steps)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->Iterations(1);

void BM_GenerateFlank(benchmark::State& state) {
  const diag::Gear& g = gearbox().meshes()[0].pair.driven();
  for (auto _ : state) benchmark::DoNotOptimize(diag::generate_tooth(g));
}
BENCHMARK(BM_GenerateFlank)->Unit(benchmark::kMillisecond);

void BM_UnloadedTeOneAngle(benchmark::State& state) {
  const diag::GearPair& p = gearbox().meshes()[0].pair;
  auto f1 = std::make_shared<const diag::Flank>(diag::generate_tooth(p.driver()).flank);
  auto f2 = std::make_shared<const diag::Flank>(diag::generate_tooth(p.driven()).flank);
  const diag::MeshFlanks mf{std::vector<std::shared_ptr<const diag::Flank>>(18, f1),
                            std::vector<std::shared_ptr<const diag::Flank>>(36, f2)};
  const std::vector<double> phi = {0.1};
  for (auto _ : state) benchmark::DoNotOptimize(diag::unloaded_transmission_error(p, mf, phi));
}
BENCHMARK(BM_UnloadedTeOneAngle)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
