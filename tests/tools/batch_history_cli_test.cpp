// `geardiag batch` as a machine's history (--healthy-first K, --healthy): the recordings put in
// time order, the first K the healthy reference, every later one compared with it (its anomaly
// score, and the damaged-shaft locator against the reference's revolution averages); a
// recording at a speed the reference never ran at is "not comparable"; the JSON's events name
// each distinct finding with the recordings that show it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;
using cli_test::run;
using cli_test::run_mpi;
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
  EXPECT_NE(r.out.find("confirmed by recording 6"), std::string::npos) << r.out;
  EXPECT_NE(html.find("anomaly score"), std::string::npos);
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
  EXPECT_EQ(e["status"], "confirmed");  // by the next recording
  EXPECT_EQ(e["confirmed_recording"], 6);
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
// reference's (the gear baselines), and the chip is an event from its first recording, on
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
  EXPECT_EQ(e["status"], "confirmed");
  EXPECT_EQ(e["confirmed_recording"], 4);
}

}  // namespace

namespace {

// A life dataset (`geardiag dataset` with a `life` block) of the three-shaft box, grade-6 gears
// (ISO 1328 pitch errors), 0.5 m/s^2 of noise, speed and torque jittered by 0.5 % and 5 %: one
// healthy history and one whose chip on z3 starts at step 3 or 4 and grows from 0.5 to 1.5 mm,
// seven recordings a day apart, the first two the reference. `tachos`: keep the tachometers or
// not (a sensor set without them).
fs::path life_dataset(const std::string& name, bool tachos) {
  const std::string gb = std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json";
  const fs::path spec = scratch("batch_history", name + ".json");
  std::ofstream(spec) << R"({"gearbox": ")" << gb << R"(", "seed": 3, "recordings_per_class": 1,
      "duration_s": 1.5, "fs_hz": 10000, "noise_m_per_s2": 0.5, "accuracy_grade": 6,
      "operating_points": {"speed_rpm": 2000, "torque_nm": 50},
      "life": {"recordings": 7, "reference": 2, "onset": [3, 4], "speed_jitter": 0.005,
               "torque_jitter": 0.05},)"
                      << (tachos ? "" : R"( "sensor_sets": [{"name": "no_tacho", "channels": ["*"],
                                                  "tachos": []}],)")
                      << R"(
      "classes": [{"name": "healthy"},
                  {"name": "chip", "faults": [{"type": "chip", "gear": "z3",
                                               "size_mm": [0.5, 1.5]}]}]})";
  const fs::path dir = scratch("batch_history", name);
  fs::remove_all(dir);
  const auto r = run("dataset " + spec.string() + " -o " + dir.string());
  EXPECT_EQ(r.code, 0) << r.out;
  return dir;
}

// A recording of the three-shaft box with grade-6 gears (seed 5: the same gears every time) and
// 0.5 m/s^2 of sensor noise of its own (`noise_seed`), by `geardiag simulate` with `more`
// scenario fields, named with the date 2026-01-<day> so that a history orders it.
fs::path dated_recording(const std::string& name, int day, int noise_seed, const std::string& more,
                         int rpm, double duration_s) {
  const std::string gb = std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json";
  const std::string stem = name + std::to_string(day);
  const fs::path sc = scratch("batch_history", stem + ".json");
  std::ofstream(sc) << R"({"accuracy_grade": 6, "seed": 5, "sensors": {"noise_m_per_s2": 0.5,
      "noise_seed": )"
                    << noise_seed << "}" << more << "}";
  const fs::path f =
      scratch("batch_history", "2026-01-" + std::string(day < 10 ? "0" : "") + std::to_string(day) +
                                   "_08-00-00_" + name + ".h5");
  const auto s = run("simulate --gearbox " + gb + " --scenario " + sc.string() + " --rpm " +
                     std::to_string(rpm) + " --duration " + std::to_string(duration_s) +
                     " --fs 10000 -o " + f.string());
  EXPECT_EQ(s.code, 0) << s.out;
  return f;
}

std::vector<json> manifest(const fs::path& dir) {
  std::vector<json> rows;
  std::ifstream in(dir / "manifest.jsonl");
  for (std::string line; std::getline(in, line);) rows.push_back(json::parse(line));
  return rows;
}

// One life of `gearbox` by `geardiag dataset` (seed `seed`: 1.5 s at 10 kHz, grade-6 gears,
// 0.3 m/s^2 of noise, 1800 rpm and 50 N m jittered by 0.5 % and 5 %), its `life` block's
// recordings, reference and onset as given and one class, `klass`: its recordings' paths in the
// manifest's order, each after a space; empty (a failure added) when it could not be made.
std::string one_life(const std::string& name, const std::string& gearbox, int seed,
                     const std::string& life, const std::string& klass) {
  const fs::path spec = scratch("batch_history", name + ".json");
  std::ofstream(spec) << R"({"gearbox": ")" << gearbox << R"(", "seed": )" << seed
                      << R"(, "recordings_per_class": 1, "duration_s": 1.5, "fs_hz": 10000,
      "noise_m_per_s2": 0.3, "accuracy_grade": 6,
      "operating_points": {"speed_rpm": 1800, "torque_nm": 50},
      "life": {)" << life
                      << R"(, "speed_jitter": 0.005, "torque_jitter": 0.05}, "classes": [)" << klass
                      << "]}";
  const fs::path dir = scratch("batch_history", name);
  fs::remove_all(dir);
  const auto made = run("dataset " + spec.string() + " -o " + dir.string());
  if (made.code != 0) {
    ADD_FAILURE() << made.out;
    return "";
  }
  std::string files;
  for (const json& row : manifest(dir)) {
    files += " " + (dir / row["file"].get<std::string>()).string();
  }
  return files;
}

// A reference that is not one state: its first recording was taken with a far noisier sensor
// (20 m/s^2 against 0.5), so that it scores over the alarm threshold against the reference
// itself. A later recording as noisy alarms at the same level: withheld (the row's alarm cleared,
// `withheld` saying why), no event. A later recording with a 1.5 mm chip is still found by the
// locator.
TEST(BatchHistory, AnAlarmAtTheLevelTheReferenceItselfShowsIsWithheld) {
  const std::string gb = std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json";
  std::string given;
  const std::vector<std::pair<double, std::string>> takes = {
      {20, ""},
      {0.5, ""},
      {0.5, ""},
      {20, ""},
      {0.5, R"(, "faults": [{"gear": "z3", "tooth": 5, "type": "chip", "size_mm": 1.5}])"}};
  for (std::size_t i = 0; i < takes.size(); ++i) {
    const fs::path sc = scratch("batch_history", "state" + std::to_string(i) + ".json");
    std::ofstream(sc) << R"({"accuracy_grade": 6, "seed": 5, "sensors": {"noise_m_per_s2": )"
                      << takes[i].first << R"(, "noise_seed": )" << 11 + i << "}" << takes[i].second
                      << "}";
    const fs::path f = scratch("batch_history", "state" + std::to_string(i) + ".h5");
    const auto s = run("simulate --gearbox " + gb + " --scenario " + sc.string() +
                       " --rpm 2000 --duration 1.5 --fs 10000 -o " + f.string());
    ASSERT_EQ(s.code, 0) << s.out;
    given += " " + f.string();
  }
  const fs::path js = scratch("batch_history", "state.json");
  const auto r = run("batch" + given + " --healthy-first 3 -o " +
                     scratch("batch_history", "state.csv").string() + " --json " + js.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const json h = read_json(js);
  const json& ref = h["recordings"][0];
  EXPECT_GT(ref["anomaly_score"].get<double>(), 25) << ref.dump(1);  // the reference's outlier
  const json& noisy = h["recordings"][3];
  EXPECT_GT(noisy["anomaly_score"].get<double>(), 25) << noisy.dump(1);
  EXPECT_EQ(noisy["alarm"], 0);
  ASSERT_EQ(noisy["withheld"].size(), 1u) << noisy.dump(1);
  EXPECT_NE(noisy["withheld"][0]["reason"].get<std::string>().find(
                "the healthy reference's own recordings score up to"),
            std::string::npos);
  EXPECT_TRUE(noisy["findings"].empty()) << noisy.dump(1);
  for (const json& e : h["events"]) EXPECT_NE(e["kind"], "baseline") << e.dump();
  bool chip = false;
  for (const json& f : h["recordings"][4]["findings"]) {
    chip = chip || (f["kind"] == "gear_damage" && f["shaft"] == "counter");
  }
  EXPECT_TRUE(chip) << h["recordings"][4].dump(1);
}

}  // namespace

// The life's draws: the same gears through a history (one simulation seed, gearbox, grade), its
// own noise per recording, a day between recordings, the reference healthy, the chip from its
// onset growing linearly to 1.5 mm at the last recording; each file dated, which the history
// orders by. A life whose onset could fall in the reference is refused naming the field.
TEST(DatasetLife, OneGearboxsDatedRecordingsAndAFaultThatGrows) {
  const std::string gb = std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/three_shaft.json";
  const fs::path spec = scratch("batch_history", "life_draws.json");
  std::ofstream(spec) << R"({"gearbox": ")" << gb << R"(", "seed": 9, "recordings_per_class": 2,
      "duration_s": 0.05, "fs_hz": 10000, "noise_m_per_s2": 0.5, "accuracy_grade": [5, 8],
      "operating_points": {"speed_rpm": [1500, 2500], "torque_nm": 50},
      "life": {"recordings": 5, "reference": 2, "start": "2026-02-27T06:00:00", "interval_h": 36,
               "speed_jitter": 0.01},
      "classes": [{"name": "crack", "faults": [{"type": "crack", "gear": "any",
                                                "depth_mm": [0.4, 2.0]}]}]})";
  const fs::path dir = scratch("batch_history", "life_draws");
  fs::remove_all(dir);
  const auto r = run("dataset " + spec.string() + " -o " + dir.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const std::vector<json> rows = manifest(dir);
  ASSERT_EQ(rows.size(), 10u);  // two histories of five
  const std::vector<std::string> times = {"2026-02-27T06:00:00", "2026-02-28T18:00:00",
                                          "2026-03-02T06:00:00", "2026-03-03T18:00:00",
                                          "2026-03-05T06:00:00"};
  for (std::size_t h = 0; h < 2; ++h) {
    const json& first = rows[5 * h];
    const int onset = first["onset_step"].get<int>();
    EXPECT_GE(onset, 2);  // never in the reference
    std::set<long> noise;
    for (int step = 0; step < 5; ++step) {
      const json& row = rows[5 * h + static_cast<std::size_t>(step)];
      EXPECT_EQ(row["history"], h);
      EXPECT_EQ(row["step"], step);
      EXPECT_EQ(row["time"], times[static_cast<std::size_t>(step)]);
      EXPECT_NE(row["file"].get<std::string>().find("-life" + std::to_string(h) + ".h5"),
                std::string::npos);
      for (const char* same : {"seed", "gearbox", "accuracy_grade", "onset_step"}) {
        EXPECT_EQ(row[same], first[same]) << same << " at step " << step;
      }
      noise.insert(row["noise_seed"].get<long>());
      EXPECT_NEAR(row["speed_rpm"].get<double>(), first["speed_rpm"].get<double>(),
                  0.021 * first["speed_rpm"].get<double>());  // two recordings' +-1 %
      if (step < onset) {
        EXPECT_EQ(row["faults"], 0) << step;
        continue;
      }
      ASSERT_EQ(row["faults"], 1) << step;
      EXPECT_EQ(row["fault1_gear"], rows[5 * h + 4]["fault1_gear"]);  // one place for life
      EXPECT_EQ(row["fault1_tooth"], rows[5 * h + 4]["fault1_tooth"]);
      const double g = onset == 4 ? 1.0 : (step - onset) / (4.0 - onset);
      EXPECT_NEAR(row["fault1_size_mm"].get<double>(), 0.4 + 1.6 * g, 1e-4) << step;
    }
    EXPECT_EQ(noise.size(), 5u);  // each recording its own noise
  }
  EXPECT_NE(rows[0]["seed"], rows[5]["seed"]);  // another machine
  // The time is in the file: a history given out of order is put in time order.
  std::string files;
  for (int step : {3, 0, 4, 1, 2})
    files += " " + (dir / rows[step]["file"].get<std::string>()).string();
  const fs::path js = scratch("batch_history", "life_draws_history.json");
  const auto b =
      run("batch" + files + " --healthy-first 2 -o " +
          scratch("batch_history", "life_draws.csv").string() + " --json " + js.string());
  ASSERT_EQ(b.code, 0) << b.out;
  const json hist = read_json(js);
  EXPECT_EQ(hist["order"], "time");
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(hist["recordings"][i]["time"], times[i]);
  }
  // Refused, naming the field: an onset inside the reference.
  const fs::path bad = scratch("batch_history", "life_bad.json");
  std::ofstream(bad) << R"({"gearbox": ")" << gb << R"(", "seed": 1, "recordings_per_class": 1,
      "duration_s": 0.05, "fs_hz": 10000, "operating_points": {"speed_rpm": 2000, "torque_nm": 50},
      "life": {"recordings": 5, "reference": 2, "onset": [1, 3]},
      "classes": [{"name": "healthy"}]})";
  const auto refused =
      run("dataset " + bad.string() + " -o " + scratch("batch_history", "life_bad").string());
  EXPECT_EQ(refused.code, 2) << refused.out;
  EXPECT_NE(refused.out.find("life.onset"), std::string::npos) << refused.out;
  // And the other fields, each named.
  const std::vector<std::pair<std::string, std::string>> bad_lives = {
      {R"("recordings": 1)", "life.recordings"},
      {R"("recordings": 5, "reference": 5)", "life.reference"},
      {R"("recordings": 5, "start": "2026-02-30T00:00:00")", "life.start"},
      {R"("recordings": 5, "interval_h": 0)", "life.interval_h"},
      {R"("recordings": 100000, "interval_h": 1000000)", "life.interval_h"},
      {R"("recordings": 5, "torque_jitter": 0.7)", "life.torque_jitter"},
      {R"("recordings": 5, "every": 2)", "life.every"}};
  for (const auto& [life, field] : bad_lives) {
    std::ofstream(bad) << R"({"gearbox": ")" << gb << R"(", "seed": 1, "recordings_per_class": 1,
        "duration_s": 0.05, "fs_hz": 10000, "operating_points": {"speed_rpm": 2000,
        "torque_nm": 50}, "life": {)"
                       << life << R"(}, "classes": [{"name": "healthy"}]})";
    const auto r2 =
        run("dataset " + bad.string() + " -o " + scratch("batch_history", "life_bad").string());
    EXPECT_EQ(r2.code, 2) << life << ": " << r2.out;
    EXPECT_NE(r2.out.find(field), std::string::npos) << life << ": " << r2.out;
  }
  EXPECT_FALSE(fs::exists(scratch("batch_history", "life_bad") / "manifest.csv"));
  // --help is the help, even where an option would take it as its value.
  const auto help = run("validate --history --help");
  EXPECT_EQ(help.code, 0) << help.out;
  EXPECT_NE(help.out.find("geardiag validate --history DIR"), std::string::npos) << help.out;
}

// The closed loop of a machine's life, through the command users run (validate --history runs
// each history as `batch --healthy-first`): the chip on z3 is confirmed within two recordings of
// its onset (the single-file locator with a healthy baseline of these gears finds 1 mm, the
// first chipped recordings are 0.5-0.83 mm), on the counter shaft, z3 among the gears named; the
// healthy history and the healthy recordings before the onset raise no event. Then the same
// lives without a tachometer: the revolutions are found in the vibration, and the verdicts hold.
TEST(BatchHistory, ALifeHistoryFindsTheChipWithinTwoRecordingsWithOrWithoutATacho) {
  for (const bool tachos : {true, false}) {
    SCOPED_TRACE(tachos ? "with tachos" : "without a tacho");
    const fs::path dir = life_dataset(tachos ? "life_tacho" : "life_no_tacho", tachos);
    const fs::path js = scratch("batch_history", tachos ? "life_v1.json" : "life_v2.json");
    const auto r = run("validate --history " + dir.string() + " --json " + js.string());
    ASSERT_EQ(r.code, 0) << r.out;
    const json v = read_json(js);
    EXPECT_EQ(v["false_alarms"]["alarms"], 0) << r.out;
    EXPECT_EQ(v["false_alarms"]["healthy_recordings"], 6);  // 5 + the chip's step 2
    EXPECT_EQ(v["failed"], 0);
    ASSERT_EQ(v["histories"].size(), 2u);
    const json& chip = v["histories"][1];
    ASSERT_TRUE(chip.contains("detection")) << chip.dump(1);
    const json& d = chip["detection"];
    EXPECT_LE(d["delay"].get<int>(), 2) << d.dump();
    EXPECT_EQ(d["shaft"], "right") << d.dump();
    EXPECT_NE(d["gear"], "wrong") << d.dump();
    EXPECT_NE(d["gear"], "none") << d.dump();
    // Every later recording was compared with the reference's revolution averages.
    for (const json& step : chip["steps"]) {
      EXPECT_TRUE(step["indicators"].contains("gear_damage/counter/score_alone")) << step.dump();
    }
  }
}

// A machine that runs at two speeds: its reference holds both (1500 and 2000 rpm, two recordings
// each), and every later recording is compared with the reference recordings of its own speed.
// The healthy ones raise nothing at either speed; one at 1750 rpm, between the two, is not
// comparable (never scored against either); a 1.5 mm chip on z3 that appears at 2000 rpm and
// stays is an event confirmed by the next recording judged, at 1500 rpm, on the counter shaft.
TEST(BatchHistory, EachRecordingIsComparedWithTheReferenceAtItsOwnSpeed) {
  struct Run {
    int rpm;
    bool chip;
  };
  const std::vector<Run> runs = {{1500, false}, {2000, false}, {1500, false}, {2000, false},
                                 {1500, false}, {2000, false}, {1750, false}, {2000, true},
                                 {1500, true},  {2000, true}};
  std::string given;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const fs::path f = dated_recording(
        "bands", static_cast<int>(i) + 1, 40 + static_cast<int>(i),
        runs[i].chip ? R"(, "faults": [{"gear": "z3", "tooth": 5, "type": "chip", "size_mm": 1.5}])"
                     : "",
        runs[i].rpm, 1.5);
    given = " " + f.string() + given;  // given newest first
  }
  const fs::path js = scratch("batch_history", "bands.json");
  const auto r = run("batch" + given + " --healthy-first 4 -o " +
                     scratch("batch_history", "bands.csv").string() + " --json " + js.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("the reference runs at 2 speeds"), std::string::npos) << r.out;
  const json h = read_json(js);
  const json& recs = h["recordings"];
  ASSERT_EQ(recs.size(), runs.size());
  for (std::size_t i = 4; i < runs.size(); ++i) {
    SCOPED_TRACE("recording " + std::to_string(i));
    if (runs[i].rpm == 1750) {
      EXPECT_EQ(recs[i]["status"], "not comparable");
      EXPECT_FALSE(recs[i].contains("anomaly_score"));
      continue;
    }
    EXPECT_EQ(recs[i]["status"], "ok");
    EXPECT_EQ(recs[i]["band"], runs[i].rpm == 1500 ? 0 : 1);
    EXPECT_EQ(recs[i]["alarm"], 0) << recs[i]["anomaly_score"];  // its own speed's reference
    if (!runs[i].chip) {
      EXPECT_TRUE(recs[i]["findings"].empty()) << recs[i]["findings"].dump(1);
    }
  }
  std::size_t confirmed = 0;
  for (const json& e : h["events"]) {
    if (e["status"] != "confirmed") continue;
    ++confirmed;
    EXPECT_EQ(e["kind"], "gear_damage") << e.dump(1);
    EXPECT_EQ(e["shaft"], "counter") << e.dump(1);
    EXPECT_EQ(e["first_recording"], 7);
    EXPECT_EQ(e["confirmed_recording"], 8);
  }
  EXPECT_EQ(confirmed, 1u) << h["events"].dump(1);
  // Under MPI (the reference, then the later recordings, then those analysed again, each round
  // split across the ranks): the same bytes.
  const std::string mpirun = GEARDIAG_MPIRUN;
  if (mpirun.empty()) return;
  const fs::path mpi_js = scratch("batch_history", "bands_mpi.json");
  const auto m =
      run_mpi("batch" + given + " --healthy-first 4 -o " +
              scratch("batch_history", "bands_mpi.csv").string() + " --json " + mpi_js.string());
  ASSERT_EQ(m.code, 0) << m.out;
  std::ifstream a(js), b(mpi_js);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(a), {}),
            std::string(std::istreambuf_iterator<char>(b), {}));
}

// A machine at two loads (30 and 60 N m at 2000 rpm), with its mesh force as the load channel
// (--load): the reference is learned per load, the healthy later recordings at either load raise
// nothing against their own load's recordings, and one at 45 N m is not comparable (it lies in
// neither band), said so.
TEST(BatchHistory, WithALoadChannelEachLoadHasItsOwnReference) {
  const std::vector<int> torques = {30, 60, 30, 60, 30, 60, 45};
  std::string given;
  for (std::size_t i = 0; i < torques.size(); ++i) {
    given += " " + dated_recording("loads", static_cast<int>(i) + 1, 60 + static_cast<int>(i),
                                   R"(, "torque_nm": )" + std::to_string(torques[i]), 2000, 1.0)
                       .string();
  }
  const fs::path js = scratch("batch_history", "loads.json");
  const auto r = run("batch" + given + " --healthy-first 4 --load z1_z2_force -o " +
                     scratch("batch_history", "loads.csv").string() + " --json " + js.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("2 operating states"), std::string::npos) << r.out;
  const json h = read_json(js);
  const json& recs = h["recordings"];
  ASSERT_EQ(recs.size(), torques.size());
  for (std::size_t i = 4; i < 6; ++i) {
    EXPECT_EQ(recs[i]["status"], "ok") << i;
    EXPECT_EQ(recs[i]["band"], torques[i] == 30 ? 0 : 1) << i;
    EXPECT_EQ(recs[i]["alarm"], 0) << recs[i]["anomaly_score"];
    EXPECT_TRUE(recs[i]["findings"].empty()) << recs[i]["findings"].dump(1);
  }
  EXPECT_EQ(recs[6]["status"], "not comparable");
  EXPECT_NE(recs[6]["error"].get<std::string>().find("at load"), std::string::npos)
      << recs[6]["error"];
  EXPECT_FALSE(recs[6].contains("anomaly_score"));
  EXPECT_TRUE(h["events"].empty()) << h["events"].dump(1);
}

// A bearing's life: the two-stage box with bearings (grade-6 gears, 0.3 m/s^2 of noise), a
// healthy history and one whose inner-race defect on input_bearing1 starts at step 3 with impacts
// of 40 m/s^2 growing to 120 m/s^2 (the gear vibration at the bearing is about 300 m/s^2 RMS).
// The defect is confirmed within two recordings of its onset, on the right bearing with the right
// fault; the healthy history raises nothing. The counter bearing's BPFO lies within 0.5 % of
// twice the input speed, and this machine's reference gives the counter bearing's outer-race
// finding once: the later recordings that give it again, scoring less than 3 dB over the
// reference's own scores of that fault, have it withheld, and the recording alone says its
// frequency lies on a shaft harmonic.
// Then the spec's bearing fields are checked: a bearing the gearbox does not list, one not at an
// accelerometer, "any" on a gearbox without bearings, a ring above 0.45 fs.
TEST(BatchHistory, ABearingDefectIsFoundAndTheReferencesOwnBearingFindingIsWithheld) {
  const std::string gb =
      std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/two_stage_23_41_19_53_bearings.json";
  const auto spec_with = [&](const std::string& name, const std::string& gearbox,
                             const std::string& fault) {
    const fs::path spec = scratch("batch_history", name + ".json");
    std::ofstream(spec) << R"({"gearbox": ")" << gearbox << R"(", "seed": 3,
      "recordings_per_class": 1, "duration_s": 1.5, "fs_hz": 10000, "noise_m_per_s2": 0.3,
      "accuracy_grade": 6, "operating_points": {"speed_rpm": 1800, "torque_nm": 50},
      "life": {"recordings": 7, "reference": 3, "onset": 3, "speed_jitter": 0.005,
               "torque_jitter": 0.05},
      "classes": [{"name": "healthy"}, {"name": "inner", "faults": [)"
                        << fault << "]}]}";
    return spec;
  };
  const fs::path spec =
      spec_with("bearing_life", gb,
                R"({"type": "bearing", "bearing": "input_bearing1", "fault": "inner_race",
                    "amplitude_m_per_s2": [40, 120]})");
  const fs::path dir = scratch("batch_history", "bearing_life");
  fs::remove_all(dir);
  const auto made = run("dataset " + spec.string() + " -o " + dir.string());
  ASSERT_EQ(made.code, 0) << made.out;
  const std::vector<json> rows = manifest(dir);
  ASSERT_EQ(rows.size(), 14u);
  EXPECT_EQ(rows[10]["fault1_type"], "bearing");
  EXPECT_EQ(rows[10]["fault1_bearing"], "input_bearing1");
  EXPECT_EQ(rows[10]["fault1_bearing_fault"], "inner_race");
  EXPECT_EQ(rows[10]["fault1_shaft"], "input");
  EXPECT_TRUE(rows[10]["fault1_gear"].is_null());
  EXPECT_DOUBLE_EQ(rows[10]["fault1_amplitude_m_per_s2"].get<double>(), 40.0);
  EXPECT_DOUBLE_EQ(rows[13]["fault1_amplitude_m_per_s2"].get<double>(), 120.0);
  // The summary counts bearing faults per bearing and fault (steps 3-6 of the second history).
  EXPECT_EQ(read_json(dir / "summary.json")["faults"],
            json({{"bearing input_bearing1 inner_race", 4}}));

  const fs::path js = scratch("batch_history", "bearing_life_v.json");
  const auto r = run("validate --history " + dir.string() + " --json " + js.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const json v = read_json(js);
  EXPECT_EQ(v["false_alarms"]["alarms"], 0) << r.out;
  ASSERT_EQ(v["histories"].size(), 2u);
  const json& inner = v["histories"][1];
  ASSERT_TRUE(inner.contains("detection")) << inner.dump(1);
  EXPECT_LE(inner["detection"]["delay"].get<int>(), 2) << inner["detection"].dump();
  EXPECT_EQ(inner["detection"]["shaft"], "right") << inner["detection"].dump();  // the bearing
  EXPECT_EQ(inner["detection"]["gear"], "right") << inner["detection"].dump();   // the fault
  int withheld = 0;
  for (const json& step : inner["steps"]) {
    for (const json& w : step.value("withheld", json::array())) {
      const std::string finding = w["finding"];
      EXPECT_NE(finding.find("counter_bearing1 outer_race"), std::string::npos) << finding;
      EXPECT_NE(w["reason"].get<std::string>().find("the healthy reference scored the same fault"),
                std::string::npos);
      ++withheld;
    }
    if (step["status"] == "reference") continue;  // the reference's own findings stay its own
    EXPECT_EQ(step["claimed"].get<std::string>().find("counter_bearing1"), std::string::npos);
  }
  EXPECT_GE(withheld, 1) << inner.dump(1);
  // The history's page plots each bearing's family lines with their growth gates.
  std::string files;
  for (std::size_t i = 7; i < 14; ++i)
    files += " " + (dir / rows[i]["file"].get<std::string>()).string();
  const fs::path page = scratch("batch_history", "bearing_life.html");
  const auto b =
      run("batch" + files + " --healthy-first 3 -o " +
          scratch("batch_history", "bearing_life.csv").string() + " --html " + page.string());
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("event: bearing inner_race input input_bearing1"), std::string::npos)
      << b.out;
  std::ifstream in(page);
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("bearing input_bearing1: most prominent envelope line"), std::string::npos);
  EXPECT_NE(html.find("BPFI: the reference&#39;s + 6 dB"), std::string::npos);
  // That reference recording alone: its counter-bearing finding says it lies on a shaft
  // harmonic, at half the confidence.
  const fs::path one = scratch("batch_history", "bearing_life_ref.json");
  ASSERT_EQ(run("analyze " + (dir / rows[8]["file"].get<std::string>()).string() + " --json " +
                one.string())
                .code,
            0);
  bool coincident = false;
  const json alone = read_json(one);
  for (const json& f : alone["findings"]) {
    if (f.value("bearing", "") != "counter_bearing1") continue;
    coincident = true;
    // 2.003 x the input's speed, and as close to 10 x the output's (23/41 x 19/53 = 0.2011).
    EXPECT_TRUE(f["evidence"]["shaft_harmonic_order"] == 2 ||
                f["evidence"]["shaft_harmonic_order"] == 10)
        << f.dump();
    EXPECT_LE(f["confidence"].get<double>(), 0.35) << f.dump();
    EXPECT_NE(f["note"].get<std::string>().find("one recording cannot tell the bearing"),
              std::string::npos);
  }
  EXPECT_TRUE(coincident) << alone["findings"].dump();

  const fs::path bad_dir = scratch("batch_history", "bearing_bad");
  const auto refused = [&](const std::string& gearbox, const std::string& fault) {
    return run("dataset " + spec_with("bearing_bad", gearbox, fault).string() + " -o " +
               bad_dir.string());
  };
  const std::string plain =
      std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/two_stage_23_41_19_53.json";
  const std::string field = "classes[1].faults[0].";
  for (const auto& [gearbox, fault, where] : std::vector<std::array<std::string, 3>>{
           {gb, R"({"type": "bearing", "bearing": "nowhere", "fault": "outer_race",
                    "amplitude_m_per_s2": 5})",
            field + "bearing"},
           {plain, R"({"type": "bearing", "bearing": "any", "fault": "outer_race",
                       "amplitude_m_per_s2": 5})",
            field + "bearing"},
           {gb, R"({"type": "bearing", "bearing": "any", "fault": "outer_race",
                    "amplitude_m_per_s2": 5, "resonance_hz": 4600})",
            field + "resonance_hz"},
           {gb, R"({"type": "bearing", "bearing": "any", "fault": "spall",
                    "amplitude_m_per_s2": 5})",
            field + "fault"},
           {gb, R"({"type": "bearing", "bearing": "any", "fault": "cage", "size_mm": 1,
                    "amplitude_m_per_s2": 5})",
            field + "size_mm"}}) {
    const auto b = refused(gearbox, fault);
    EXPECT_EQ(b.code, 2) << fault << "\n" << b.out;
    EXPECT_NE(b.out.find(where), std::string::npos) << b.out;
    EXPECT_FALSE(fs::exists(bad_dir / "manifest.csv"));
  }
}

// Wear in a history is judged against the reference's own spread, not the single recording's
// fixed 4 dB: per mesh, the reference recordings' growth values g_1..g_n give the threshold
// mean + t_{n-1}(0.99) max(s, 0.1 dB) sqrt(1 + 1/n) (a prediction bound: a healthy recording
// exceeds it with probability 1 % for Gaussian levels). The life of the 23/41 x 19/53 box with
// grade-6 gears, six reference recordings, the input pinion's flanks wearing from 5 um at step 6
// to 40 um at step 9: the thresholds in the JSON are the closed form of the reference's own
// values (to 1e-9 dB), every later recording has a wear finding on a mesh exactly when its growth
// exceeds that mesh's threshold, and the wear is confirmed on the input shaft within two
// recordings of its onset, by a recording whose growth is still under 4 dB (the single
// recording's threshold would have flagged neither of the two). Under MPI, the same bytes.
TEST(BatchHistory, WearIsJudgedAgainstTheReferencesOwnSpread) {
  const std::string gb = std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/two_stage_23_41_19_53.json";
  const std::string files = one_life(
      "wear_life", gb, 3, R"("recordings": 10, "reference": 6, "onset": 6)",
      R"({"name": "wear", "faults": [{"type": "wear", "gear": "p1", "depth_um": [5, 40]}]})");
  ASSERT_FALSE(files.empty());
  const fs::path js = scratch("batch_history", "wear_life_batch.json");
  const fs::path html = scratch("batch_history", "wear_life_batch.html");
  const auto b = run("batch" + files + " --healthy-first 6 -o " +
                     scratch("batch_history", "wear_life_batch.csv").string() + " --json " +
                     js.string() + " --html " + html.string());
  ASSERT_EQ(b.code, 0) << b.out;
  const json out = read_json(js);
  ASSERT_EQ(out["states"].size(), 1u) << out["states"].dump();
  const json& wear = out["states"][0]["wear"];
  ASSERT_EQ(wear.size(), 2u) << wear.dump();
  const json& rec = out["recordings"];
  ASSERT_EQ(rec.size(), 10u);
  constexpr double kT5 = 3.3649299989072;  // Student's t, 5 degrees of freedom, 99 %
  for (const auto& [mesh, w] : wear.items()) {
    SCOPED_TRACE(mesh);
    const std::string key = "wear/" + mesh + "/growth_db";
    std::vector<double> g;
    for (std::size_t i = 0; i < 6; ++i) g.push_back(rec[i]["indicators"][key].get<double>());
    double mean = 0, ss = 0;
    for (double x : g) mean += x / 6;
    for (double x : g) ss += (x - mean) * (x - mean);
    const double sd = std::sqrt(ss / 5);
    EXPECT_EQ(w["reference_recordings"], 6);
    EXPECT_NEAR(w["mean_db"].get<double>(), mean, 1e-9);
    EXPECT_NEAR(w["sd_db"].get<double>(), sd, 1e-9);
    const double threshold = mean + kT5 * std::max(sd, 0.1) * std::sqrt(1 + 1.0 / 6);
    EXPECT_NEAR(w["threshold_db"].get<double>(), threshold, 1e-9);
    for (std::size_t i = 6; i < rec.size(); ++i) {
      const double growth = rec[i]["indicators"][key].get<double>();
      bool found = false;
      for (const json& f : rec[i]["findings"]) {
        if (f["kind"] != "wear") continue;
        const auto& gears = f["gears"];
        if (mesh != gears[0].get<std::string>() + "_" + gears[1].get<std::string>()) continue;
        found = true;
        EXPECT_NEAR(f["evidence"]["threshold_db"].get<double>(), threshold, 1e-9);
      }
      EXPECT_EQ(found, growth > threshold) << "recording " << i << ": growth " << growth;
    }
  }
  bool confirmed = false;
  for (const json& e : out["events"]) {
    EXPECT_NE(e["kind"], "gear_damage") << e.dump();  // no chip, crack or spall here
    if (e["kind"] != "wear") continue;
    EXPECT_EQ(e["shaft"], "input") << e.dump();
    EXPECT_GE(e["first_recording"].get<int>(), 6) << e.dump();
    if (e["status"] != "confirmed") continue;
    confirmed = true;
    const int at = e["confirmed_recording"].get<int>();
    EXPECT_LE(at, 8) << e.dump();
    EXPECT_LT(rec[at]["indicators"]["wear/p1_w1/growth_db"].get<double>(), 4.0) << e.dump();
  }
  EXPECT_TRUE(confirmed) << out["events"].dump(1);
  std::ifstream page(html);
  const std::string text{std::istreambuf_iterator<char>(page), {}};
  EXPECT_NE(text.find("p1_w1: flagged above"), std::string::npos);
  // Under MPI (the thresholds found on the first rank, sent to every rank before the later
  // recordings are analysed): the same bytes.
  const std::string mpirun = GEARDIAG_MPIRUN;
  if (!mpirun.empty()) {
    const fs::path mpi_js = scratch("batch_history", "wear_life_mpi.json");
    const auto m = run_mpi("batch" + files + " --healthy-first 6 -o " +
                           scratch("batch_history", "wear_life_mpi.csv").string() + " --json " +
                           mpi_js.string());
    ASSERT_EQ(m.code, 0) << m.out;
    std::ifstream a(js), b(mpi_js);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(a), {}),
              std::string(std::istreambuf_iterator<char>(b), {}));
  }
  // With two reference recordings there is no spread to read: the fixed threshold, said so.
  const auto two = run("batch" + files + " --healthy-first 2 -o " +
                       scratch("batch_history", "wear_life_two.csv").string());
  ASSERT_EQ(two.code, 0) << two.out;
  EXPECT_NE(two.out.find("keeps the single recording's threshold of 4 dB"), std::string::npos)
      << two.out;
}

// A ball defect read from the cage line: a defective ball's impacts come and go as the cage
// carries it through the load zone, so the envelope gains a line at the cage's rate (FTF). The
// 17/44 x 21/50 box with bearings, a ball of its input bearing (input_bearing2) defective from
// step 3, its impacts growing from 20 to 60 m/s^2: the cage line rises more than 6 dB over the
// reference's at once, before the bearing decision of a single recording names the ball, and the
// history confirms the rolling-element defect by the next recording, on that bearing, with the
// finding saying it was the cage line. Every growth finding stands on a line the reference held
// steady (its values within 6 dB), and no other bearing becomes an event.
TEST(BatchHistory, ABallDefectIsReadFromTheCageLine) {
  const std::string gb =
      std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/two_stage_17_44_21_50_bearings.json";
  const std::string files =
      one_life("ball_life", gb, 5, R"("recordings": 8, "reference": 3, "onset": 3)",
               R"({"name": "ball", "faults": [{"type": "bearing", "bearing": "input_bearing2",
          "fault": "rolling_element", "amplitude_m_per_s2": [20, 60]}]})");
  ASSERT_FALSE(files.empty());
  const fs::path js = scratch("batch_history", "ball_life_batch.json");
  const auto b =
      run("batch" + files + " --healthy-first 3 -o " +
          scratch("batch_history", "ball_life_batch.csv").string() + " --json " + js.string());
  ASSERT_EQ(b.code, 0) << b.out;
  const json out = read_json(js);
  const json& rec = out["recordings"];
  ASSERT_EQ(rec.size(), 8u);
  std::size_t confirmed = 0;
  for (const json& e : out["events"]) {
    if (e["kind"] != "bearing" || e["status"] != "confirmed") continue;
    ++confirmed;
    EXPECT_EQ(e["bearing"], "input_bearing2") << e.dump();
    EXPECT_EQ(e["fault"], "rolling_element") << e.dump();
    EXPECT_EQ(e["first_recording"], 3) << e.dump();
    EXPECT_EQ(e["confirmed_recording"], 4) << e.dump();
  }
  EXPECT_EQ(confirmed, 1u) << out["events"].dump(1);
  for (std::size_t i : {3u, 4u}) {
    bool cage = false;
    for (const json& f : rec[i]["findings"]) {
      cage =
          cage || (f["kind"] == "bearing" && f["bearing"] == "input_bearing2" &&
                   f["fault"] == "rolling_element" &&
                   f["note"].get<std::string>().find("modulated by the cage") != std::string::npos);
    }
    EXPECT_TRUE(cage) << "recording " << i << ": " << rec[i]["findings"].dump(1);
  }
  for (std::size_t i = 3; i < rec.size(); ++i) {
    for (const json& f : rec[i]["findings"]) {
      if (f["kind"] != "bearing" || !f["evidence"].contains("growth_db")) continue;
      // The line behind it: the one that grew by growth_db over the reference's largest.
      bool steady = false;
      for (const char* family : {"BPFO", "BPFI", "BSF", "FTF"}) {
        const std::string key = "bearing/" + f["bearing"].get<std::string>() + "/" + family + "_db";
        if (!rec[i]["indicators"].contains(key)) continue;
        double lo = 1e9, hi = -1e9;
        for (std::size_t r = 0; r < 3; ++r) {
          lo = std::min(lo, rec[r]["indicators"][key].get<double>());
          hi = std::max(hi, rec[r]["indicators"][key].get<double>());
        }
        if (std::abs(rec[i]["indicators"][key].get<double>() - hi -
                     f["evidence"]["growth_db"].get<double>()) < 1e-9) {
          steady = hi - lo < 6.0;
        }
      }
      EXPECT_TRUE(steady) << "recording " << i << ": " << f.dump();
    }
  }
}

// The locator's gates from the reference's own spread. A root crack of the 23/41 box's counter
// wheel w1 from step 3, 0.78 mm growing to 0.92 mm: its score against the reference wanders
// across the single recording's threshold of 20 from one recording to the next (16.6, 25.1,
// 14.1, 30.9, 17.4), so that threshold alone would see it in two recordings that are not
// successive, and never confirm it. Each shaft's gate is the prediction bound of its reference
// scores' logarithm, the scale pooled over the shafts (the closed form checked here); a shaft in
// the locator's uncertain band (12, 20] over its gate is a finding of the history. The crack is
// confirmed by the recording after its onset, on the counter shaft. The same gears healthy:
// scores over their gates occur (the bound is for 1 % per shaft and recording), but under the
// uncertain band, and no event.
TEST(BatchHistory, TheLocatorsGatesComeFromTheReferencesOwnSpread) {
  const std::string gb = std::string(GEARDIAG_TESTDATA_DIR) + "/gearbox/two_stage_23_41_19_53.json";
  const std::string files = one_life(
      "crack_life", gb, 4, R"("recordings": 8, "reference": 3, "onset": 3)",
      R"({"name": "crack", "faults": [{"type": "crack", "gear": "w1", "depth_mm": [0.78, 0.92]}]},
         {"name": "healthy"})");
  ASSERT_FALSE(files.empty());
  std::string crack, healthy;
  std::istringstream split(files);
  for (std::string f; split >> f;) {
    (f.find("-crack-") != std::string::npos ? crack : healthy) += " " + f;
  }
  constexpr double kT6 = 3.1426684032909828;  // Student's t, 6 degrees of freedom, 99 %
  bool healthy_over_gate = false;
  for (const std::string& which : {std::string("crack"), std::string("healthy")}) {
    SCOPED_TRACE(which);
    const fs::path js = scratch("batch_history", "locator_gate_" + which + ".json");
    const fs::path html = scratch("batch_history", "locator_gate_" + which + ".html");
    const auto b = run("batch" + (which == "crack" ? crack : healthy) + " --healthy-first 3 -o " +
                       scratch("batch_history", "locator_gate.csv").string() + " --json " +
                       js.string() + " --html " + html.string());
    ASSERT_EQ(b.code, 0) << b.out;
    std::ifstream page(html);
    const std::string text{std::istreambuf_iterator<char>(page), {}};
    EXPECT_NE(text.find("reference gate (alone)"), std::string::npos);
    EXPECT_NE(text.find("uncertain above"), std::string::npos);
    EXPECT_NE(b.out.find("a healthy recording exceeds one with probability 1 %"), std::string::npos)
        << b.out;
    const json out = read_json(js);
    const json& rec = out["recordings"];
    ASSERT_EQ(rec.size(), 8u);
    const json& gates = out["states"][0]["locator"];
    ASSERT_EQ(gates.size(), 6u) << gates.dump();  // three shafts, two scores
    // The closed form: per score, the logarithms' mean per shaft, their spread pooled.
    std::map<std::string, double> gate;
    for (const std::string suffix : {"/score", "/score_alone"}) {
      double ss = 0;
      int dof = 0;
      std::map<std::string, double> mean;
      for (const auto& [key, g] : gates.items()) {
        if (!key.ends_with(suffix)) continue;
        double m = 0;
        for (std::size_t r = 0; r < 3; ++r) {
          m += std::log(rec[r]["indicators"]["gear_damage/" + key].get<double>()) / 3;
        }
        for (std::size_t r = 0; r < 3; ++r) {
          const double d = std::log(rec[r]["indicators"]["gear_damage/" + key].get<double>()) - m;
          ss += d * d;
        }
        dof += 2;
        mean[key] = m;
      }
      ASSERT_EQ(dof, 6);
      const double sd = std::sqrt(ss / dof);
      for (const auto& [key, m] : mean) {
        const json& g = gates[key];
        EXPECT_EQ(g["from_spread"], true);
        EXPECT_EQ(g["dof"], 6);
        EXPECT_NEAR(g["mean_log"].get<double>(), m, 1e-9) << key;
        EXPECT_NEAR(g["sd_log"].get<double>(), sd, 1e-9) << key;
        gate[key] = std::exp(m + kT6 * std::max(sd, 0.05) * std::sqrt(1 + 1.0 / 3));
        EXPECT_NEAR(g["threshold"].get<double>(), gate[key], 1e-9 * gate[key]) << key;
      }
    }
    // Every later gear_damage finding exceeds a gate; one of the history's own lies in the
    // uncertain band; what was withheld scored under both gates.
    auto score = [&](std::size_t i, const std::string& key) {
      return rec[i]["indicators"]["gear_damage/" + key].get<double>();
    };
    for (std::size_t i = 3; i < rec.size(); ++i) {
      for (const auto& [key, g] : gate) {
        healthy_over_gate = healthy_over_gate || (which == "healthy" && score(i, key) > g);
      }
      for (const json& f : rec[i]["findings"]) {
        if (f["kind"] != "gear_damage") continue;
        const std::string shaft = f["shaft"];
        EXPECT_TRUE(score(i, shaft + "/score") > gate[shaft + "/score"] ||
                    score(i, shaft + "/score_alone") > gate[shaft + "/score_alone"])
            << "recording " << i << ": " << f.dump();
        if (!f["evidence"].contains("gate")) continue;
        const double s = score(i, shaft + "/score");
        EXPECT_GT(s, 12.0) << f.dump();
        EXPECT_LE(s, 20.0) << f.dump();
        EXPECT_NEAR(f["evidence"]["gate"].get<double>(), gate[shaft + "/score"], 1e-9 * s);
        EXPECT_NE(f["note"].get<std::string>().find("uncertain band"), std::string::npos);
      }
      for (const json& w : rec[i].value("withheld", json::array())) {
        const std::string text = w.dump();
        for (const std::string shaft : {"input", "counter", "output"}) {
          if (text.find("gear_damage") == std::string::npos ||
              text.find(shaft) == std::string::npos) {
            continue;
          }
          EXPECT_LE(score(i, shaft + "/score"), gate[shaft + "/score"]) << text;
          EXPECT_LE(score(i, shaft + "/score_alone"), gate[shaft + "/score_alone"]) << text;
        }
      }
    }
    std::size_t events = 0;
    for (const json& e : out["events"]) {
      if (e["kind"] != "gear_damage") continue;
      ++events;
      EXPECT_EQ(which, "crack") << e.dump();
      EXPECT_EQ(e["shaft"], "counter") << e.dump();
      EXPECT_EQ(e["status"], "confirmed") << e.dump();
      EXPECT_EQ(e["first_recording"], 3) << e.dump();
      EXPECT_EQ(e["confirmed_recording"], 4) << e.dump();
    }
    EXPECT_EQ(events, which == "crack" ? 1u : 0u) << out["events"].dump(1);
    if (which == "crack") {  // the premise: the onset's recording under the single threshold
      EXPECT_LT(score(3, "counter/score"), 20.0);
      EXPECT_GT(score(3, "counter/score"), 12.0);
    }
  }
  EXPECT_TRUE(healthy_over_gate);  // the premise: the uncertain band's floor is what holds there
}
