// geardiag dataset through the binary (tools/cmd_dataset.cpp): a tiny spec (three classes, two
// recordings of 0.2 s each) is generated with one and two threads and, when geardiag is built with
// MPI, under `mpirun -np 2`; every output must be byte-identical (recording k depends on (seed, k)
// only). Resuming after kill -9 or deleted files regenerates the same bytes; a folder made from
// another spec is refused; bad specs exit 2 naming the field with nothing written.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli_run.hpp"
#include "dataset_files.hpp"
#include "diag/io/hdf5.hpp"

namespace {

namespace fs = std::filesystem;
using cli_test::run;
using cli_test::run_mpi;
using cli_test::slurp;
using cli_test::write_text;

fs::path scratch(const std::string& name) { return cli_test::scratch("dataset_cli", name); }

// The tiny spec: the minimal form at 0.2 s, the gearbox given relative to the spec's
// folder, plus noise, pitch errors, runout and a class with two faults at once. `extra` adds
// top-level fields, `classes` replaces the classes.
const char* const kClasses =
    R"([{"name": "healthy"},
        {"name": "crack", "faults": [{"type": "crack", "gear": "any", "depth_mm": [0.5, 2.0]}]},
        {"name": "two", "faults": [{"type": "chip", "gear": ["z1", "z2"], "size_mm": [0.5, 2.0]},
                                   {"type": "missing", "gear": "z4", "tooth": 3}]}])";

fs::path write_spec(const std::string& name, int seed = 42, const std::string& extra = "",
                    const std::string& classes = kClasses) {
  const fs::path spec = scratch(name);
  const fs::path gb = cli_test::testdata_gearbox("three_shaft.json");
  std::ofstream(spec) << R"({"gearbox": ")" << fs::relative(gb, spec.parent_path()).string()
                      << R"(", "seed": )" << seed << R"(, "recordings_per_class": 2,
 "duration_s": 0.2, "fs_hz": 20000,
 "operating_points": {"speed_rpm": [1200, 2400], "torque_nm": [30, 80]},
 "noise_m_per_s2": [0, 0.05], "accuracy_grade": [5, 7], "runout_um": [0, 10], )"
                      << extra << R"( "classes": )" << classes << "}";
  return spec;
}

// A reference dataset made once with one thread.
const fs::path& reference() {
  static const fs::path dir = [] {
    const fs::path d = scratch("ref");
    const auto r =
        run("dataset " + write_spec("spec.json").string() + " -o " + d.string() + " --jobs 1");
    EXPECT_EQ(r.code, 0) << r.out;
    return d;
  }();
  return dir;
}

TEST(DatasetCli, ManifestTruthAndClassBalance) {
  const auto ref = cli_test::folder_files(reference());
  // 6 recordings, dataset.json, manifest.csv, manifest.jsonl, summary.json.
  ASSERT_EQ(ref.size(), 10u);
  std::istringstream csv(ref.at("manifest.csv"));
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("file,id,index,class,gearbox,seed,speed_rpm,torque_nm,", 0), 0u);
  EXPECT_NE(header.find("fault2_type,fault2_gear,fault2_shaft,fault2_tooth,fault2_size_mm"),
            std::string::npos);
  std::istringstream jsonl(ref.at("manifest.jsonl"));
  int rows = 0;
  while (std::getline(jsonl, line)) {
    const nlohmann::json row = nlohmann::json::parse(line);
    ++rows;
    ASSERT_TRUE(ref.count(row["file"].get<std::string>())) << line;
    // The drawn values are within the spec's ranges.
    EXPECT_GE(row["speed_rpm"].get<double>(), 1200);
    EXPECT_LE(row["speed_rpm"].get<double>(), 2400);
    EXPECT_GE(row["accuracy_grade"].get<int>(), 5);
    EXPECT_LE(row["accuracy_grade"].get<int>(), 7);
    const std::string cls = row["class"];
    EXPECT_EQ(row["faults"].get<int>(), cls == "healthy" ? 0 : cls == "crack" ? 1 : 2);
    if (cls == "two") {
      EXPECT_TRUE(row["fault1_gear"] == "z1" || row["fault1_gear"] == "z2") << line;
      EXPECT_EQ(row["fault1_shaft"], row["fault1_gear"] == "z1" ? "input" : "counter");
      EXPECT_EQ(row["fault2_gear"], "z4");
      EXPECT_EQ(row["fault2_tooth"], 3);
    }
    // The file's /truth holds the faults the manifest names and the dataset's row.
    const diag::RecordingReader reader(reference() / row["file"].get<std::string>());
    const nlohmann::json truth = nlohmann::json::parse(reader.truth_json());
    EXPECT_EQ(truth["dataset"]["manifest"], row);
    EXPECT_EQ(truth["dataset"]["scenario"]["faults"].size(), row["faults"].get<std::size_t>());
    EXPECT_EQ(reader.metadata().at("dataset_class"), cls);
  }
  EXPECT_EQ(rows, 6);
  const nlohmann::json summary = nlohmann::json::parse(ref.at("summary.json"));
  for (const char* cls : {"healthy", "crack", "two"}) {
    EXPECT_EQ(summary["classes"][cls]["recordings"], 2) << cls;
  }
}

TEST(DatasetCli, ByteIdenticalWhateverTheThreadsAndResumable) {
  const auto ref = cli_test::folder_files(reference());
  const fs::path spec = write_spec("spec.json");
  const fs::path two = scratch("two_threads");
  auto r = run("dataset " + spec.string() + " -o " + two.string() + " --jobs 2");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(cli_test::folder_files(two), ref);
  // Two recordings and the manifest deleted, a temporary file of a killed run left: the same
  // command regenerates exactly what was there.
  fs::remove(two / "recordings/000001-healthy.h5");
  fs::remove(two / "recordings/000004-two.h5");
  fs::remove(two / "manifest.csv");
  std::ofstream(two / "recordings/000004-two.h5.tmp-99999") << "half a file";
  r = run("dataset " + spec.string() + " -o " + two.string() + " --jobs 2");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("resuming: 4 of 6"), std::string::npos) << r.out;
  EXPECT_EQ(cli_test::folder_files(two), ref);
}

TEST(DatasetCli, KilledRunLeavesOnlyCompleteFilesAndResumes) {
  const auto ref = cli_test::folder_files(reference());
  const fs::path spec = write_spec("spec.json");
  const fs::path dir = scratch("killed");
  // SIGKILL part-way (wherever it lands: the assertions hold for any moment).
  std::system(("timeout -s KILL 0.7 " + std::string(GEARDIAG_BINARY) + " dataset " + spec.string() +
               " -o " + dir.string() + " --jobs 2 >/dev/null 2>&1")
                  .c_str());
  if (fs::exists(dir / "recordings")) {
    for (const auto& e : fs::directory_iterator(dir / "recordings")) {
      const std::string name = e.path().filename();
      if (name.find(".tmp-") != std::string::npos) continue;  // removed by the next run
      // A file under its final name is complete: the same bytes as the reference's.
      EXPECT_EQ(slurp(e.path()), ref.at("recordings/" + name)) << name;
    }
  }
  const auto r = run("dataset " + spec.string() + " -o " + dir.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(cli_test::folder_files(dir), ref);
}

TEST(DatasetCli, FolderOfAnotherSpecIsRefused) {
  const auto before = cli_test::folder_files(reference());
  const auto r =
      run("dataset " + write_spec("spec43.json", 43).string() + " -o " + reference().string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("different spec"), std::string::npos) << r.out;
  EXPECT_EQ(cli_test::folder_files(reference()), before);
  // A non-empty folder that is not a dataset is refused too.
  const fs::path other = scratch("not_a_dataset");
  fs::create_directories(other);
  std::ofstream(other / "notes.txt") << "mine";
  const auto r2 = run("dataset " + write_spec("spec.json").string() + " -o " + other.string());
  EXPECT_EQ(r2.code, 2) << r2.out;
  EXPECT_NE(r2.out.find("not a geardiag dataset"), std::string::npos) << r2.out;
}

TEST(DatasetCli, BadSpecsExit2NamingTheFieldBeforeWriting) {
  struct Case {
    std::string extra, classes, message;
  };
  const Case cases[] = {
      {"", R"([{"name": "c", "faults": [{"type": "crack", "gear": "z9", "depth_mm": 1}]}])",
       "classes[0].faults[0].gear: 'z9' is not a gear"},
      {"", R"([{"name": "c", "recordings": -2}])", "classes[0].recordings: must be >= 0"},
      {R"("recordings_per_class": -1,)", kClasses, "recordings_per_class: must be >= 1"},
      {R"("noise": 1,)", kClasses, "noise: unknown field"},
      {"",
       R"([{"name": "c", "faults": [{"type": "crack", "gear": "z1", "depth_mm": 1, "size_mm": 1}]}])",
       "classes[0].faults[0].size_mm: is not a field of a crack fault"},
      {"",
       R"([{"name": "c", "faults": [{"type": "chip", "gear": "z1", "tooth": 18, "size_mm": 1}]}])",
       "classes[0].faults[0].tooth: 18 is not a tooth of gear 'z1'"},
      // fs below 2.5 x the third mesh harmonic of z1-z2 at 2400 rpm (3 x 18 x 40 Hz = 2160 Hz).
      {R"("fs_hz": 5000,)", kClasses, "fs_hz: 5000 Hz is below 2.5 x 2160 Hz"},
  };
  int i = 0;
  for (const Case& c : cases) {
    std::string text = slurp(write_spec("bad.json", 42, c.extra, c.classes));
    // A field given twice: keep the case's (the first) by renaming the base spec's.
    for (const char* key : {"\"recordings_per_class\"", "\"fs_hz\""}) {
      if (c.extra.find(key) != std::string::npos) text.replace(text.find(key), 1, "\"_");
    }
    const fs::path spec = write_text(scratch("bad" + std::to_string(i) + ".json"), text);
    const fs::path out = scratch("bad_out" + std::to_string(i++));
    const auto r = run("dataset " + spec.string() + " -o " + out.string());
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find(c.message), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out)) << out;
  }
}

TEST(DatasetCli, MpiTwoRanksGiveTheSingleProcessBytes) {
  const std::string mpirun = GEARDIAG_MPIRUN;
  if (mpirun.empty()) GTEST_SKIP() << "geardiag built without MPI";
  const auto ref = cli_test::folder_files(reference());
  const fs::path dir = scratch("mpi");
  const auto r = run_mpi("dataset " + write_spec("spec.json").string() + " -o " + dir.string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(cli_test::folder_files(dir), ref);
}

}  // namespace

namespace {

// geardiag batch over the reference dataset, a missing file among them: one row per file in the
// order given, the missing one a row with its error; the two healthy recordings are the
// baseline. Under mpirun -np 2 the table is the same bytes.
// The time column from a date-time in the file's name, in the forms a logger writes
// (separated or compact); none in the name and none in the metadata: empty.
TEST(BatchCli, TheTimeStampComesFromTheFileName) {
  const fs::path src = scratch("stamp_source.h5");
  const auto s = run("simulate --gearbox " +
                     (fs::path(GEARDIAG_TESTDATA_DIR) / "gearbox/three_shaft.json").string() +
                     " --rpm 1500 --duration 0.3 --fs 10000 -o " + src.string());
  ASSERT_EQ(s.code, 0) << s.out;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"pump_2024-03-01_12-30-00.h5", "2024-03-01T12:30:00"},
      {"rig20240301T123005x.h5", "2024-03-01T12:30:05"},
      {"run_7_of_12.h5", ""}};
  std::string args;
  for (const auto& [name, stamp] : cases) {
    fs::copy_file(src, scratch(name), fs::copy_options::overwrite_existing);
    args += " " + scratch(name).string();
  }
  const fs::path table = scratch("stamps.csv");
  const auto r = run("batch" + args + " -o " + table.string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::istringstream csv(slurp(table));
  std::string line;
  std::getline(csv, line);  // header
  for (const auto& [name, stamp] : cases) {
    ASSERT_TRUE(std::getline(csv, line));
    EXPECT_NE(line.find(name + "," + stamp + ",ok,"), std::string::npos) << line.substr(0, 200);
  }
}

TEST(BatchCli, OneRowPerFileAFailedFileIsARowAndMpiGivesTheSameTable) {
  const fs::path ref = reference();
  // Two healthy 0.5 s recordings of the same gearbox and channels: the baseline, and the first
  // two rows (the baseline's feature set needs parts of >= 4096 samples, >= 3 parts in all, and
  // a scored recording of >= 4096 samples: the dataset's 0.2 s files are analysed but not scored,
  // the error column says why).
  std::string args, baseline = " --baseline";
  for (const char* rpm : {"1500", "2100"}) {
    const fs::path b = scratch(std::string("healthy_") + rpm + ".h5");
    const auto s = run("simulate --gearbox " +
                       (fs::path(GEARDIAG_TESTDATA_DIR) / "gearbox/three_shaft.json").string() +
                       " --rpm " + rpm + " --torque 50 --duration 0.5 --fs 20000 -o " + b.string());
    ASSERT_EQ(s.code, 0) << s.out;
    args += " " + b.string();
    baseline += " " + b.string();
  }
  for (const char* id : {"000002-crack", "000004-two"}) {
    args += " " + (ref / "recordings" / (std::string(id) + ".h5")).string();
  }
  args += " " + (ref / "recordings/missing.h5").string() + baseline;
  const fs::path table = scratch("batch.csv"), html = scratch("batch.html");
  const auto r = run("batch" + args + " -o " + table.string() + " --html " + html.string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::istringstream csv(slurp(table));
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("file,time,status,error,speed_rpm,anomaly_score,alarm,alarm_threshold,"
                         "findings,",
                         0),
            0u)
      << header.substr(0, 200);
  std::vector<std::string> lines;
  while (std::getline(csv, line)) lines.push_back(line);
  ASSERT_EQ(lines.size(), 5u);
  // Analysed and scored: status ok, no error, an anomaly score with the threshold 25.
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_NE(lines[i].find(".h5,,ok,,"), std::string::npos) << lines[i].substr(0, 300);
    EXPECT_NE(lines[i].find(",25.0,"), std::string::npos) << lines[i].substr(0, 300);
  }
  for (std::size_t i = 2; i < 4; ++i) {
    EXPECT_NE(lines[i].find(".h5,,ok,\"baseline: "), std::string::npos) << lines[i].substr(0, 300);
  }
  EXPECT_NE(lines[4].find("missing.h5,,error,"), std::string::npos) << lines[4];
  EXPECT_NE(lines[4].find("no such file"), std::string::npos) << lines[4];
  EXPECT_NE(slurp(html).find("anomaly score"), std::string::npos);
  const std::string mpirun = GEARDIAG_MPIRUN;
  if (mpirun.empty()) return;
  const fs::path mpi_table = scratch("batch_mpi.csv");
  const auto rm = run_mpi("batch" + args + " -o " + mpi_table.string());
  ASSERT_EQ(rm.code, 0) << rm.out;
  EXPECT_EQ(slurp(mpi_table), slurp(table));
}

}  // namespace

namespace {

// validate --dataset over the reference dataset: every manifest row is analysed once and counted
// in the confusion matrix (two recordings per class), and the JSON says which shaft was named.
TEST(ValidateDatasetCli, ConfusionMatrixCountsEveryRecording) {
  const fs::path js = scratch("validate.json");
  const auto r = run("validate --dataset " + reference().string() + " --json " + js.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json rep = nlohmann::json::parse(slurp(js));
  ASSERT_EQ(rep["recordings"].size(), 6u);
  for (const char* cls : {"healthy", "crack", "two"}) {
    int n = 0;
    for (const auto& [named, count] : rep["classes"][cls]["predicted"].items())
      n += count.get<int>();
    EXPECT_EQ(n, 2) << cls;
  }
  for (const auto& row : rep["recordings"]) {
    EXPECT_TRUE(row["named"].is_string());
    EXPECT_FALSE(row.contains("error")) << row.dump();
  }
}

}  // namespace
