// Face-gear stiffness / static-TE tables from a file: the HDF5 layout against the CSV one (the
// same table gives bit-identical tables and simulations), and the refusals of bad HDF5 tables.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "diag/error.hpp"
#include "diag/io/hdf5_arrays.hpp"
#include "sim/facegear/description.hpp"
#include "sim/facegear/face_gear.hpp"

namespace fg = sim::facegear;
namespace fs = std::filesystem;

namespace {

// One flank's table in the file units: angle [deg], load [N m], k [N m/rad] (n_a x n_l), e0 [urad].
struct FileTable {
  std::vector<double> angle_deg, load_nm, k, e0_urad;
};

// A table with angle and load dependence and values that are not round in binary (so a lossy
// conversion anywhere would show): 20 angles over the 24 deg mesh period of 15 teeth.
FileTable make_table(double k0, double phase) {
  FileTable t;
  for (int i = 0; i < 20; ++i) {
    t.angle_deg.push_back(1.2 * i);
    t.e0_urad.push_back(13.7 * std::cos(0.3 * i + phase));
  }
  t.load_nm = {1.0, 7.3, 55.5, 300.0};
  for (int i = 0; i < 20; ++i) {
    for (double load : t.load_nm) {
      t.k.push_back(k0 * (1.0 + 0.1 * std::cos(0.3 * i + phase)) * std::pow(load / 300.0, 0.1));
    }
  }
  return t;
}

void write_csv(const fs::path& path, const FileTable& drive, const FileTable& coast) {
  std::ofstream out(path);
  out << "flank,angle_deg,load_nm,stiffness_nm_per_rad,e0_urad\n";
  char line[256];
  for (const auto& [name, t] : {std::pair{"drive", &drive}, std::pair{"coast", &coast}}) {
    for (std::size_t i = 0; i < t->angle_deg.size(); ++i) {
      for (std::size_t j = 0; j < t->load_nm.size(); ++j) {
        std::snprintf(line, sizeof line, "%s,%.17g,%.17g,%.17g,%.17g\n", name, t->angle_deg[i],
                      t->load_nm[j], t->k[i * t->load_nm.size() + j], t->e0_urad[i]);
        out << line;
      }
    }
  }
}

// The layout of description.hpp: the drive flank on the root grid, the coast flank on its own.
std::vector<diag::Hdf5Array> hdf5_layout(const FileTable& drive, const FileTable& coast) {
  return {{"/angle_deg", {}, drive.angle_deg, "deg"},
          {"/load_nm", {}, drive.load_nm, "N m"},
          {"/drive/stiffness_nm_per_rad",
           {drive.angle_deg.size(), drive.load_nm.size()},
           drive.k,
           "N m/rad"},
          {"/drive/e0_urad", {}, drive.e0_urad, "urad"},
          {"/coast/angle_deg", {}, coast.angle_deg, "deg"},
          {"/coast/load_nm", {}, coast.load_nm, "N m"},
          {"/coast/stiffness_nm_per_rad",
           {coast.angle_deg.size(), coast.load_nm.size()},
           coast.k,
           "N m/rad"},
          {"/coast/e0_urad", {}, coast.e0_urad, "urad"}};
}

class FaceGearTables : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = geardiag_test::scratch_dir("fg_tables"); }
  void TearDown() override { fs::remove_all(dir_); }

  fg::Description describe(const std::string& table) const {
    return fg::parse_description(
        nlohmann::json{{"face_gear_pair",
                        {{"pinion_teeth", 15}, {"gear_teeth", 121}, {"stiffness_table", table}}},
                       {"input", {{"speed_rpm", 9000}, {"torque_nm", 40}}}},
        (dir_ / "fg.json").string());
  }
  std::string error_of(const std::vector<diag::Hdf5Array>& arrays) const {
    diag::write_hdf5_arrays(dir_ / "bad.h5", arrays);
    try {
      describe("bad.h5");
    } catch (const diag::InputError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

void expect_same(const fg::FlankTable& a, const fg::FlankTable& b) {
  EXPECT_EQ(a.angle_rad, b.angle_rad);
  EXPECT_EQ(a.load_nm, b.load_nm);
  EXPECT_EQ(a.k, b.k);
  EXPECT_EQ(a.e0_rad, b.e0_rad);
}

}  // namespace

// Same numbers, two files: the tables must be equal to the bit (the HDF5 reader converts nothing
// but deg -> rad and urad -> rad, as the CSV reader does), so the simulations are too: the DTE,
// mesh torque and contact state of a run with backlash and load-dependent stiffness compared
// with ==, no tolerance.
TEST_F(FaceGearTables, Hdf5AndCsvGiveBitIdenticalSimulation) {
  const FileTable drive = make_table(9.1e5, 0.0), coast = make_table(8.7e5, 1.1);
  write_csv(dir_ / "t.csv", drive, coast);
  diag::write_hdf5_arrays(dir_ / "t.h5", hdf5_layout(drive, coast));
  const fg::Description c = describe("t.csv"), h = describe("t.h5");
  expect_same(c.pair.drive, h.pair.drive);
  expect_same(c.pair.coast, h.pair.coast);
  ASSERT_EQ(h.pair.drive.k.size(), 80u);
  fg::RunOptions o;
  o.transient_periods = 20;
  o.record_periods = 60;
  const fg::Model mc(c.pair, c.operating), mh(h.pair, h.operating);
  o.steps_per_period = fg::rk4_steps_per_period(mc);
  const fg::Trace tc = fg::run(mc, o), th = fg::run(mh, o);
  EXPECT_EQ(tc.dte, th.dte);
  EXPECT_EQ(tc.mesh_torque, th.mesh_torque);
  EXPECT_EQ(tc.contact, th.contact);
  EXPECT_GT(tc.max_abs_mesh_torque, 0.0);
}

// Each bad table is refused with an InputError naming the file, the dataset and the reason.
TEST_F(FaceGearTables, BadHdf5TablesNameDatasetAndReason) {
  const FileTable drive = make_table(9.1e5, 0.0), coast = make_table(8.7e5, 1.1);
  const std::vector<diag::Hdf5Array> good = hdf5_layout(drive, coast);
  EXPECT_EQ(error_of(good), "");
  auto with = [&](const std::string& path, std::vector<double> data,
                  std::vector<std::size_t> shape = {}) {
    std::vector<diag::Hdf5Array> a = good;
    for (auto& x : a) {
      if (x.path == path) {
        x.data = std::move(data);
        x.shape = std::move(shape);
      }
    }
    return a;
  };
  auto without = [&](const std::string& path) {
    std::vector<diag::Hdf5Array> a;
    for (const auto& x : good) {
      if (x.path != path) a.push_back(x);
    }
    return a;
  };
  auto expect_error = [&](const std::vector<diag::Hdf5Array>& arrays,
                          const std::vector<std::string>& parts) {
    const std::string e = error_of(arrays);
    EXPECT_NE(e.find("bad.h5"), std::string::npos) << e;
    for (const std::string& p : parts) EXPECT_NE(e.find(p), std::string::npos) << e;
  };
  // Non-monotone angle.
  std::vector<double> angles = drive.angle_deg;
  std::swap(angles[3], angles[4]);
  expect_error(with("/angle_deg", angles), {"/angle_deg", "strictly increasing"});
  // An angle beyond one mesh period (24 deg for 15 teeth).
  angles = coast.angle_deg;
  angles.back() = 24.0;
  expect_error(with("/coast/angle_deg", angles), {"/coast/angle_deg", "mesh period"});
  // Negative stiffness.
  std::vector<double> k = drive.k;
  k[45] = -k[45];
  expect_error(with("/drive/stiffness_nm_per_rad", k, {20, 4}),
               {"/drive/stiffness_nm_per_rad", "must be > 0"});
  // Wrong shape: load x angle instead of angle x load; 1-D; e0 of the wrong length.
  expect_error(with("/drive/stiffness_nm_per_rad", drive.k, {4, 20}),
               {"/drive/stiffness_nm_per_rad", "shape 4 x 20", "20 x 4"});
  expect_error(with("/coast/stiffness_nm_per_rad", coast.k),
               {"/coast/stiffness_nm_per_rad", "shape 80"});
  expect_error(with("/drive/e0_urad", std::vector<double>(19, 0.0)),
               {"/drive/e0_urad", "one value per angle"});
  // Missing datasets.
  expect_error(without("/coast/e0_urad"), {"/coast/e0_urad", "missing dataset"});
  expect_error(without("/load_nm"), {"/load_nm", "missing dataset", "/drive/load_nm"});
  // Loads not increasing, negative, NaN.
  expect_error(with("/load_nm", {1.0, 7.3, 7.3, 300.0}), {"/load_nm", "strictly increasing"});
  expect_error(with("/coast/load_nm", {-1.0, 7.3, 55.5, 300.0}), {"/coast/load_nm", ">= 0"});
  expect_error(with("/load_nm", {1.0, std::numeric_limits<double>::quiet_NaN(), 55.5, 300.0}),
               {"/load_nm", "NaN"});
  // A file that is not HDF5 under an .h5 name goes to the CSV reader, which names its header.
  std::ofstream(dir_ / "bad.h5", std::ios::trunc) << "not a table\n";
  try {
    describe("bad.h5");
    ADD_FAILURE() << "accepted a file that is neither HDF5 nor CSV";
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("header"), std::string::npos) << e.what();
  }
}

// A load outside the table: constant
// extrapolation, the nearest load's row (FlankTable), documented in description.hpp and
// docs/face-gear.md. Below the first load and above the last the stiffness equals that row's
// exactly; within the grid it is linear in load (bilinear with the angle), so the midpoint of two
// loads is the mean of their rows (to rounding, 1e-15 relative).
TEST(FaceGearTableLoads, OutsideTheGridTheNearestLoadRowIsUsed) {
  fg::FlankTable t;
  const double period = 2 * std::numbers::pi / 15;
  t.angle_rad = {0.0, period / 2};
  t.e0_rad = {0.0, 0.0};
  t.load_nm = {10.0, 100.0};
  t.k = {1e6, 2e6,   // angle 0: loads 10, 100
         3e6, 5e6};  // angle period / 2
  t.validate("t", "drive", period);
  EXPECT_EQ(t.stiffness(0.0, 0.0, period), 1e6);
  EXPECT_EQ(t.stiffness(0.0, 9.99, period), 1e6);
  EXPECT_EQ(t.stiffness(0.0, 100.0, period), 2e6);
  EXPECT_EQ(t.stiffness(0.0, 1e5, period), 2e6);
  EXPECT_EQ(t.stiffness(period / 2, 1e5, period), 5e6);
  EXPECT_NEAR(t.stiffness(0.0, 55.0, period), 1.5e6, 1.5e6 * 1e-15);
  // Angle midway across the period end (from period / 2 back to 0 + period), above the grid.
  EXPECT_NEAR(t.stiffness(0.75 * period, 500.0, period), 3.5e6, 3.5e6 * 1e-15);
}

// Backlash < 0 and the other scenario fields out of range: InputError naming the field, from the
// scenario as from the description (tests/simulator/face_gear_test.cpp).
TEST(FaceGearTableLoads, ScenarioRefusesNegativeBacklashAndScale) {
  fg::Description d = fg::parse_description(
      nlohmann::json{{"face_gear_pair", {{"pinion_teeth", 15}, {"gear_teeth", 121}}}}, "fg.json");
  auto error = [&](const nlohmann::json& sc) {
    try {
      fg::apply_scenario(d, sc, "sc.json");
    } catch (const diag::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error({{"backlash_um", -1}}).find("sc.json: backlash_um"), std::string::npos);
  EXPECT_NE(error({{"stiffness_scale", 0}}).find("sc.json: stiffness_scale"), std::string::npos);
  EXPECT_NE(error({{"torque_nm", -3}}).find("sc.json: torque_nm"), std::string::npos);
  EXPECT_NE(error({{"static_te_scale", -1}}).find("sc.json: static_te_scale"), std::string::npos);
  EXPECT_EQ(error({{"backlash_um", 0}}), "");
  EXPECT_EQ(d.pair.half_backlash_rad, 0.0);
}
