// geardiag analyze --gear-baseline: a healthy recording of the same gears given to the
// damaged-shaft locator (NA4-style comparison fused with the recording's own answer,
// detect/gear/gear_damage.hpp step 7), end to end through the binary, and its bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;
using cli_test::run;

fs::path scratch(const std::string& name) { return cli_test::scratch("gear_baseline_cli", name); }

const std::string kGearbox =
    (fs::path(GEARDIAG_TESTDATA_DIR) / "gearbox/three_shaft.json").string();

// 1.5 s of the three-shaft box at 2000 rpm (12.5 output revolutions: the locator needs 8).
fs::path simulated(const std::string& name, const std::string& extra = "") {
  const fs::path p = scratch(name);
  if (!fs::exists(p)) {
    const auto s = run("simulate --gearbox " + kGearbox + " --rpm 2000 --duration 1.5 --fs 10000 " +
                       extra + " -o " + p.string());
    EXPECT_EQ(s.code, 0) << s.out;
  }
  return p;
}

TEST(GearBaselineCli, TheLocatorComparesWithTheBaselineAndReportsBothScores) {
  const fs::path js = scratch("with.json");
  const auto a = run("analyze " + simulated("rec.h5").string() + " --gearbox " + kGearbox +
                     " --gear-baseline " + simulated("rec.h5").string() + " --json " + js.string());
  ASSERT_EQ(a.code, 0) << a.out;
  const auto j = nlohmann::json::parse(std::ifstream(js));
  const auto& g = j["gear_damage"];
  ASSERT_EQ(g["shafts"].size(), 3u) << g.dump(1);
  int compared = 0;
  for (const auto& s : g["shafts"]) {
    // A shaft with a score: its score alone is a number too (both answers were taken).
    if (s["compared_with_baseline"].get<bool>()) {
      ++compared;
      EXPECT_TRUE(s["score_alone"].is_number()) << s.dump();
    }
  }
  EXPECT_EQ(compared, 3) << g.dump(1);
  // The recording against itself: nothing changed, and the healthy box alone flags nothing.
  EXPECT_EQ(g["status"], "healthy") << g.dump(1);
  EXPECT_NE(g["note"].get<std::string>().find("baseline"), std::string::npos) << g.dump(1);

  // Without --gear-baseline the key is there and null.
  const fs::path js0 = scratch("without.json");
  ASSERT_EQ(run("analyze " + simulated("rec.h5").string() + " --json " + js0.string()).code, 0);
  const auto j0 = nlohmann::json::parse(std::ifstream(js0));
  for (const auto& s : j0["gear_damage"]["shafts"]) {
    EXPECT_FALSE(s["compared_with_baseline"].get<bool>());
    EXPECT_TRUE(s["score_alone"].is_null());
  }
}

TEST(GearBaselineCli, BadBaselineExitsWithCodeTwoNamingTheOptionAndWritesNothing) {
  const fs::path js = scratch("never.json");
  const auto missing = run("analyze " + simulated("rec.h5").string() + " --gear-baseline " +
                           scratch("nope.h5").string() + " --json " + js.string());
  EXPECT_EQ(missing.code, 2) << missing.out;
  EXPECT_NE(missing.out.find("--gear-baseline"), std::string::npos) << missing.out;
  EXPECT_NE(missing.out.find("nope.h5"), std::string::npos) << missing.out;
  EXPECT_FALSE(fs::exists(js));

  // A baseline without a tacho: the locator cannot average it by revolution.
  const fs::path csv = scratch("no_tacho.csv");
  {
    std::ofstream out(csv);
    out << "time,acc\n";
    for (int i = 0; i < 20000; ++i) out << i / 10000.0 << "," << std::sin(0.37 * i) << "\n";
  }
  const auto no_tacho = run("analyze " + simulated("rec.h5").string() + " --gear-baseline " +
                            csv.string() + " --json " + js.string());
  EXPECT_EQ(no_tacho.code, 2) << no_tacho.out;
  EXPECT_NE(no_tacho.out.find("--gear-baseline"), std::string::npos) << no_tacho.out;
  EXPECT_NE(no_tacho.out.find("tacho"), std::string::npos) << no_tacho.out;
  EXPECT_FALSE(fs::exists(js));

  // A CSV recording has no /gearbox: without --gearbox there is nothing to locate on.
  const auto no_gearbox =
      run("analyze " + csv.string() + " --gear-baseline " + simulated("rec.h5").string());
  EXPECT_EQ(no_gearbox.code, 2) << no_gearbox.out;
  EXPECT_NE(no_gearbox.out.find("needs a gearbox"), std::string::npos) << no_gearbox.out;
}

}  // namespace
