// `geardiag batch` as a machine's history (--healthy-first K, --healthy): the recordings put in
// time order, the first K the healthy reference, every later one compared with it (its anomaly
// score, and the damaged-shaft locator against the reference's revolution averages); a
// recording at a speed the reference never ran at is "not comparable"; the JSON's events name
// each distinct finding with the recordings that show it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;
using cli_test::run;
using cli_test::scratch;
using nlohmann::json;

json read_json(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

// The SpectraQuest gearbox files (measured, 2560 Hz, no description): healthy at loads 0-80 %,
// then broken tooth at the same loads, given out of order under names carrying one date each
// (a day apart, healthy first). The first three in time order are the reference: the healthy
// 60 % and 80 % loads raise no alarm, the first broken file does, and so does every one after it:
// one event, from the first broken recording.
TEST(BatchHistory, TheAlarmComesOnTheFirstBrokenRecordingAndNotBefore) {
  const fs::path data = fs::path(GEARDIAG_SHARED_DATA_DIR) / "spectraquest-gearbox";
  if (!fs::exists(data / "b30hz0.csv.gz")) GTEST_SKIP() << "no measured data under " << data;
  const std::vector<std::string> in_time = {"h30hz0", "h30hz20", "h30hz40", "h30hz60", "h30hz80",
                                            "b30hz0", "b30hz20", "b30hz40", "b30hz60", "b30hz80"};
  std::vector<fs::path> dated;
  for (std::size_t i = 0; i < in_time.size(); ++i) {
    const fs::path link =
        scratch("batch_history", "2024-03-" + std::string(i < 9 ? "0" : "") +
                                     std::to_string(i + 1) + "_08-00-00_" + in_time[i] + ".csv.gz");
    fs::remove(link);
    fs::create_symlink(data / (in_time[i] + ".csv.gz"), link);
    dated.push_back(link);
  }
  std::string given;  // out of time order
  for (std::size_t i : {7, 2, 9, 0, 5, 3, 8, 1, 6, 4}) given += " " + dated[i].string();
  const fs::path js = scratch("batch_history", "history.json");
  const fs::path page = scratch("batch_history", "history.html");
  const fs::path reports = scratch("batch_history", "reports");
  fs::remove_all(reports);
  const auto r = run("batch" + given + " --fs 2560 --healthy-first 3 -o " +
                     scratch("batch_history", "table.csv").string() + " --json " + js.string() +
                     " --html " + page.string() + " --reports " + reports.string());
  ASSERT_EQ(r.code, 0) << r.out;
  // The HTML: against the dates, the event and every recording listed.
  std::ifstream in(page);
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("days since the first recording (2024-03-01T08:00:00)"), std::string::npos);
  EXPECT_NE(html.find("<h2>Events</h2>"), std::string::npos);
  EXPECT_NE(html.find("b30hz80"), std::string::npos);
  EXPECT_NE(r.out.find("event: baseline anomaly: from recording 5"), std::string::npos) << r.out;
  const json h = read_json(js);
  EXPECT_EQ(h["order"], "time");
  ASSERT_EQ(h["recordings"].size(), 10u);
  for (std::size_t i = 0; i < 10; ++i) {
    const json& rec = h["recordings"][i];
    EXPECT_EQ(rec["index"], i);
    EXPECT_NE(rec["file"].get<std::string>().find(in_time[i]), std::string::npos) << i;
    EXPECT_EQ(rec["status"], i < 3 ? "reference" : "ok") << i;
    // Its own report, linked from the history's page, says what the row says: the alarm is a
    // finding there too (from the first broken recording on), and a quiet recording has none.
    const fs::path own = rec["report"].get<std::string>();
    EXPECT_EQ(own.parent_path(), reports);
    EXPECT_NE(html.find("<a href=\"reports/" + own.filename().string() + "\">"), std::string::npos)
        << own;
    std::ifstream report_in(own);
    const std::string report((std::istreambuf_iterator<char>(report_in)),
                             std::istreambuf_iterator<char>());
    EXPECT_NE(report.find(in_time[i]), std::string::npos) << own;
    const std::size_t n_findings = rec["findings"].size();
    EXPECT_NE(report.find(n_findings == 0 ? std::string("Verdict: no finding")
                                          : "Verdict: " + std::to_string(n_findings) +
                                                (n_findings == 1 ? " finding" : " findings")),
              std::string::npos)
        << own;
    if (i >= 5) {
      EXPECT_NE(report.find("baseline ALARM"), std::string::npos) << own;
    }
    // No description, so no gear baseline is tried (and no error said of it).
    EXPECT_FALSE(rec.contains("error")) << rec["error"];
    if (i < 3) continue;
    EXPECT_EQ(rec["alarm"], i >= 5 ? 1 : 0) << rec["file"] << " score " << rec["anomaly_score"];
  }
  ASSERT_EQ(h["events"].size(), 1u) << h["events"].dump(1);
  const json& e = h["events"][0];
  EXPECT_EQ(e["kind"], "baseline");
  EXPECT_EQ(e["first_recording"], 5);
  EXPECT_EQ(e["first_time"], "2024-03-06T08:00:00");
  EXPECT_EQ(e["recordings"], json({5, 6, 7, 8, 9}));
  EXPECT_EQ(e["trend"].size(), 5u);
  EXPECT_EQ(h["reference"].size(), 3u);
}

// Simulated recordings of the three-shaft box without dates (the order given): two at 1500 rpm
// the reference, then one at 1500 and one at 2000 rpm. The 2000 rpm one is not comparable: no
// anomaly score or alarm in its row, said why. An explicit reference (--healthy) gives the same
// verdicts; a reference as long as the list, or beside --baseline, is refused (exit 2).
TEST(BatchHistory, ARecordingAtAnotherSpeedIsNotComparable) {
  const std::string gb = std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json";
  std::vector<std::string> files;
  int seed = 1;
  for (const int rpm : {1500, 1500, 1500, 2000}) {
    const fs::path f = scratch("batch_history", "run" + std::to_string(seed) + ".h5");
    const auto s =
        run("simulate --gearbox " + gb + " --rpm " + std::to_string(rpm) +
            " --duration 0.5 --fs 20000 --seed " + std::to_string(seed++) + " -o " + f.string());
    ASSERT_EQ(s.code, 0) << s.out;
    files.push_back(f.string());
  }
  const fs::path js = scratch("batch_history", "speeds.json");
  const std::string table = " -o " + scratch("batch_history", "speeds.csv").string();
  const auto r = run("batch " + files[0] + " " + files[1] + " " + files[2] + " " + files[3] +
                     " --healthy-first 2" + table + " --json " + js.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("not every recording says when it was made"), std::string::npos) << r.out;
  json h = read_json(js);
  EXPECT_EQ(h["order"], "given");
  ASSERT_EQ(h["recordings"].size(), 4u);
  EXPECT_EQ(h["recordings"][2]["status"], "ok");
  EXPECT_TRUE(h["recordings"][2].contains("anomaly_score"));
  const json& fast = h["recordings"][3];
  EXPECT_EQ(fast["status"], "not comparable");
  EXPECT_FALSE(fast.contains("anomaly_score"));
  EXPECT_FALSE(fast.contains("alarm"));
  EXPECT_NE(fast["error"].get<std::string>().find("outside the reference's"), std::string::npos);
  for (const json& f : fast["findings"]) EXPECT_NE(f["kind"], "baseline");

  const auto explicit_ref = run("batch " + files[2] + " " + files[3] + " --healthy " + files[0] +
                                " " + files[1] + table + " --json " + js.string());
  ASSERT_EQ(explicit_ref.code, 0) << explicit_ref.out;
  h = read_json(js);
  ASSERT_EQ(h["recordings"].size(), 4u);
  EXPECT_EQ(h["recordings"][0]["status"], "reference");
  EXPECT_EQ(h["recordings"][3]["status"], "not comparable");

  const auto all_reference =
      run("batch " + files[0] + " " + files[1] + " --healthy-first 2" + table);
  EXPECT_EQ(all_reference.code, 2) << all_reference.out;
  EXPECT_NE(all_reference.out.find("--healthy-first"), std::string::npos) << all_reference.out;
  const auto both = run("batch " + files[2] + " --healthy-first 1 --baseline " + files[0] + table);
  EXPECT_EQ(both.code, 2) << both.out;
}

// A chip that appears and grows on the counter shaft's z3, on grade-6 gears (ISO 1328 pitch
// errors) with 0.5 m/s^2 of sensor noise: alone, each recording's locator sees nothing under the
// gears' own pitch errors; the history compares every recording's revolution averages with the
// reference's first (the gear baseline), and the chip is an event from its first recording, on
// the counter shaft; the healthy recording after the reference stays clean.
TEST(BatchHistory, AChipOnAGradeSixGearIsAnEventFromItsFirstRecording) {
  const std::string gb = std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json";
  std::vector<std::string> files;
  const std::string healthy =
      R"("accuracy_grade": 6, "seed": 5, "sensors": {"noise_m_per_s2": 0.5,)";
  const std::vector<std::string> scenarios = {
      "{" + healthy + R"( "noise_seed": 11}})", "{" + healthy + R"( "noise_seed": 12}})",
      "{" + healthy + R"( "noise_seed": 13}})",
      "{" + healthy + R"( "noise_seed": 14}, "faults": [{"gear": "z3", "tooth": 5, "type": "chip",
          "size_mm": 1.0}]})",
      "{" + healthy + R"( "noise_seed": 15}, "faults": [{"gear": "z3", "tooth": 5, "type": "chip",
          "size_mm": 1.5}]})"};
  for (std::size_t i = 0; i < scenarios.size(); ++i) {
    const fs::path sc = scratch("batch_history", "chip" + std::to_string(i) + ".json");
    std::ofstream(sc) << scenarios[i];
    const fs::path f = scratch("batch_history", "chip" + std::to_string(i) + ".h5");
    const auto s = run("simulate --gearbox " + gb + " --scenario " + sc.string() +
                       " --rpm 2000 --duration 1.5 --fs 10000 -o " + f.string());
    ASSERT_EQ(s.code, 0) << s.out;
    files.push_back(f.string());
  }
  // Alone, the first chipped recording shows nothing.
  const fs::path alone = scratch("batch_history", "alone.json");
  ASSERT_EQ(run("analyze " + files[3] + " --json " + alone.string()).code, 0);
  EXPECT_TRUE(read_json(alone)["findings"].empty()) << read_json(alone)["findings"].dump(1);

  const fs::path js = scratch("batch_history", "chip.json");
  std::string given;
  for (const std::string& f : files) given += " " + f;
  const auto r = run("batch" + given + " --healthy-first 2 -o " +
                     scratch("batch_history", "chip.csv").string() + " --json " + js.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const json h = read_json(js);
  EXPECT_TRUE(h["recordings"][2]["findings"].empty()) << h["recordings"][2].dump(1);
  ASSERT_EQ(h["events"].size(), 1u) << h["events"].dump(1);
  const json& e = h["events"][0];
  EXPECT_EQ(e["kind"], "gear_damage");
  EXPECT_EQ(e["shaft"], "counter");
  EXPECT_EQ(e["first_recording"], 3);
  EXPECT_EQ(e["recordings"], json({3, 4}));
}

}  // namespace
