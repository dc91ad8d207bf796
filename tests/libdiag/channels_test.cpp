// The channel contract (diag/io/channels.hpp): roles stored and read back, format-1 files read
// with their roles inferred, channel maps and --tacho, and the inference of tachos in measured
// files.
#include "diag/io/channels.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "diag/error.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/hdf5.hpp"

namespace {

namespace fs = std::filesystem;

diag::Gearbox three_shaft() {
  return diag::load_gearbox(fs::path(GEARDIAG_TESTDATA_DIR) / "gearbox" / "three_shaft.json");
}

diag::Signal signal(const std::string& name, std::vector<double> x, double fs = 10000) {
  diag::Signal s;
  s.name = name;
  s.fs_hz = fs;
  s.samples = std::move(x);
  return s;
}

std::vector<double> noise(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::vector<double> x(n);
  for (double& v : x) v = g(rng);
  return x;
}

// A 0/5 V pulse train, `rate_hz` pulses per second, 10 % duty, with 2 % noise.
std::vector<double> pulses(std::size_t n, double fs, double rate_hz, unsigned seed = 1) {
  std::vector<double> x = noise(n, seed);
  for (std::size_t i = 0; i < n; ++i) {
    const double phase = std::fmod(static_cast<double>(i) / fs * rate_hz, 1.0);
    x[i] = (phase < 0.1 ? 5.0 : 0.0) + 0.1 * x[i];
  }
  return x;
}

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".h5");
}

// A format-1 file made by the last format-1 writer (testdata/recordings/README.md): the roles
// come back as the simulator meant them, from directions, units and its documented names.
TEST(Channels, AFormat1RecordingIsReadWithItsRolesInferred) {
  const diag::Recording rec = diag::read_recording(fs::path(GEARDIAG_TESTDATA_DIR) / "recordings" /
                                                   "format1_three_shaft.h5");
  ASSERT_FALSE(rec.notes.empty());
  EXPECT_NE(rec.notes.front().find("format-1"), std::string::npos);
  EXPECT_TRUE(rec.roles_stated);
  const diag::Signal& along = rec.require("counter_bearing1_along_loa_z3_z4", "test");
  EXPECT_EQ(along.role, diag::Role::kVibration);
  EXPECT_EQ(along.shaft, "counter");
  EXPECT_EQ(along.mesh, "z3_z4");
  EXPECT_EQ(rec.require("input_bearing1_along_loa", "test").mesh, "");
  EXPECT_EQ(rec.require("input_bearing1_vertical", "test").shaft, "input");
  EXPECT_EQ(rec.require("z1_z2_force", "test").role, diag::Role::kForce);
  EXPECT_EQ(rec.require("z1_z2_dte", "test").role, diag::Role::kDisplacement);
  EXPECT_EQ(rec.require("z1_z2_contact", "test").role, diag::Role::kOther);
  EXPECT_EQ(rec.require("input_angle", "test").role, diag::Role::kAngle);
  ASSERT_EQ(rec.tachos.size(), 3u);
  const diag::Signal* t = diag::shaft_tacho(rec, "counter");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->role, diag::Role::kTacho);
  EXPECT_EQ(diag::pulses_per_rev(*t), 1);
  // The sensors of a shaft by the contract: the counter shaft's eight bearing channels per
  // bearing (two meshes x two directions + horizontal + vertical) at two bearings.
  const diag::Gearbox gb = three_shaft();
  EXPECT_EQ(diag::shaft_sensors(rec, gb, "counter").size(), 12u);
  EXPECT_EQ(diag::sensor_meshes(along, gb), (std::vector<int>{1}));
}

TEST(Channels, RolesShaftMeshAndPprSurviveAWriteAndRead) {
  diag::Recording rec;
  rec.signals.push_back(signal("acc", noise(100, 1)));
  rec.signals.back().shaft = "input";
  rec.signals.back().mesh = "z1_z2";
  rec.signals.push_back(signal("f", noise(100, 2)));
  rec.signals.back().role = diag::Role::kForce;
  rec.tachos.push_back(signal("key", pulses(100, 10000, 500)));
  rec.tachos.back().role = diag::Role::kTacho;
  rec.tachos.back().shaft = "input";
  rec.tachos.back().ppr = 4;
  rec.speed_rpm = 1797;
  rec.roles_stated = false;
  const fs::path p = temp_file("roles");
  diag::write_recording(p, rec);
  const diag::Recording back = diag::read_recording(p);
  fs::remove(p);
  EXPECT_TRUE(back.notes.empty());
  EXPECT_FALSE(back.roles_stated);
  EXPECT_EQ(back.speed_rpm, 1797);
  EXPECT_EQ(back.signals[0].role, diag::Role::kVibration);
  EXPECT_EQ(back.signals[0].shaft, "input");
  EXPECT_EQ(back.signals[0].mesh, "z1_z2");
  EXPECT_EQ(back.signals[1].role, diag::Role::kForce);
  ASSERT_EQ(back.tachos.size(), 1u);
  EXPECT_EQ(back.tachos[0].role, diag::Role::kTacho);
  EXPECT_EQ(back.tachos[0].ppr, 4);
  EXPECT_EQ(diag::sensor_channels(back), (std::vector<std::size_t>{0}));
}

TEST(Channels, AChannelMapSetsRolesAndMovesTachos) {
  diag::Recording rec;
  rec.signals.push_back(signal("acc1", noise(100, 1)));
  rec.signals.push_back(signal("key", pulses(100, 10000, 500)));
  const auto map = diag::parse_channel_map(nlohmann::json::parse(R"({"channels": [
      {"name": "acc1", "role": "vibration", "unit": "m/s^2", "direction": "vertical",
       "location": "drive_end"},
      {"name": "key", "role": "tacho", "shaft": "input", "ppr": 2}]})"),
                                           "map.json");
  const diag::Gearbox gb = three_shaft();
  diag::apply_channel_map(rec, map, &gb, "map.json");
  ASSERT_EQ(rec.signals.size(), 1u);
  EXPECT_EQ(rec.signals[0].unit, "m/s^2");
  EXPECT_EQ(rec.signals[0].direction, diag::Direction::kVertical);
  EXPECT_EQ(rec.signals[0].location, "drive_end");
  ASSERT_EQ(rec.tachos.size(), 1u);
  EXPECT_EQ(rec.tachos[0].name, "key");
  EXPECT_EQ(rec.tachos[0].ppr, 2);
  EXPECT_EQ(diag::shaft_tacho(rec, "input"), &rec.tachos[0]);
}

void expect_refused(const std::string& map_text, const std::string& expected) {
  diag::Recording rec;
  rec.signals.push_back(signal("acc1", noise(100, 1)));
  const diag::Gearbox gb = three_shaft();
  try {
    diag::apply_channel_map(rec, diag::parse_channel_map(nlohmann::json::parse(map_text), "m.json"),
                            &gb, "m.json");
    ADD_FAILURE() << "accepted: " << map_text;
  } catch (const diag::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("m.json"), std::string::npos) << e.what();
  }
}

TEST(Channels, BadChannelMapsAreRefusedNamingTheFileAndField) {
  expect_refused(R"({"channels": [{"name": "acc2"}]})", "no such channel");
  expect_refused(R"({"channels": [{"name": "acc1", "colour": "red"}]})", "unknown field");
  expect_refused(R"({"channels": [{"name": "acc1", "role": "noise"}]})", "unknown role");
  expect_refused(R"({"channels": [{"name": "acc1", "role": "tacho"}]})", "needs the shaft");
  expect_refused(R"({"channels": [{"name": "acc1", "shaft": "spindle"}]})", "not a shaft");
  expect_refused(R"({"channels": [{"name": "acc1", "mesh": "z9_z8"}]})", "not a mesh");
  expect_refused(R"({"channels": [{"name": "acc1", "role": "tacho", "shaft": "input",
                    "ppr": 0}]})",
                 "ppr");
  expect_refused(R"({"channels": [{"name": "acc1"}, {"name": "acc1"}]})", "twice");
  expect_refused(R"({"chanels": []})", "unknown field");
}

TEST(Channels, TachoOptionIsChannelShaftAndPulsesPerRevolution) {
  const auto e = diag::parse_tacho_option("key=input:60", "--tacho");
  EXPECT_EQ(e.name, "key");
  EXPECT_EQ(*e.shaft, "input");
  EXPECT_EQ(*e.ppr, 60);
  EXPECT_EQ(*e.role, diag::Role::kTacho);
  EXPECT_EQ(*diag::parse_tacho_option("k=out", "--tacho").ppr, 1);
  for (const char* bad : {"key", "=input", "key=", "key=input:0", "key=input:x", "key=:2"}) {
    EXPECT_THROW(diag::parse_tacho_option(bad, "--tacho"), diag::InputError) << bad;
  }
}

TEST(Channels, PulseTrainsAreTwoLevelAndVibrationIsNot) {
  const double fs = 10000;
  const auto rate = diag::pulse_train_rate_hz(pulses(20000, fs, 33.3), fs);
  ASSERT_TRUE(rate.has_value());
  EXPECT_NEAR(*rate, 33.3, 0.05);  // edges quantised to 1/fs over 2 s: 3e-4 relative
  EXPECT_FALSE(diag::pulse_train_rate_hz(noise(20000, 3), fs).has_value());
  std::vector<double> sine(20000);
  for (std::size_t i = 0; i < sine.size(); ++i)
    sine[i] = std::sin(2 * std::numbers::pi * 33.3 * static_cast<double>(i) / fs);
  EXPECT_FALSE(diag::pulse_train_rate_hz(sine, fs).has_value());
}

// Measured files: a pulse train is a tacho of the shaft its rate and name say; a tacho is never
// vibration; what cannot be placed is said and left out.
TEST(Channels, TachosOfMeasuredFilesAreInferredFromNameAndRate) {
  const diag::Gearbox gb = three_shaft().with_input_speed_rpm(1500);
  const double f_in = gb.shaft_speed_hz(gb.shaft_index("input"));
  const double f_counter = gb.shaft_speed_hz(gb.shaft_index("counter"));
  const double fs = 10000;
  const std::size_t n = 40000;
  auto measured = [&](const std::string& name, std::vector<double> x) {
    diag::Recording rec;
    rec.signals.push_back(signal("acc", noise(n, 7), fs));
    rec.signals.push_back(signal(name, std::move(x), fs));
    rec.roles_stated = false;
    return rec;
  };
  // Named after the shaft, at the shaft's rate 2 % off the nominal.
  for (const char* name : {"input", "tacho_input", "input_tacho", "Tacho"}) {
    auto rec = measured(name, pulses(n, fs, f_in * 1.02));
    const auto notes = diag::infer_tachos(rec, &gb);
    ASSERT_EQ(rec.tachos.size(), 1u) << name;
    EXPECT_EQ(rec.tachos[0].shaft, "input") << name;
    EXPECT_EQ(rec.tachos[0].ppr, 1);
    EXPECT_EQ(diag::sensor_channels(rec).size(), 1u);
    ASSERT_FALSE(notes.empty());
    EXPECT_NE(notes[0].find("tacho of shaft input"), std::string::npos) << notes[0];
  }
  // Unnamed: by its rate alone; four pulses per revolution of a named shaft.
  {
    auto rec = measured("ch2", pulses(n, fs, f_counter));
    diag::infer_tachos(rec, &gb);
    ASSERT_EQ(rec.tachos.size(), 1u);
    EXPECT_EQ(rec.tachos[0].shaft, "counter");
  }
  {
    auto rec = measured("counter_key", pulses(n, fs, 4 * f_counter));
    diag::infer_tachos(rec, &gb);
    ASSERT_EQ(rec.tachos.size(), 1u);
    EXPECT_EQ(rec.tachos[0].ppr, 4);
  }
  // A rate no shaft turns at: not a tacho, not vibration either.
  {
    auto rec = measured("ch2", pulses(n, fs, 2.7 * f_in));
    const auto notes = diag::infer_tachos(rec, &gb);
    EXPECT_TRUE(rec.tachos.empty());
    EXPECT_EQ(diag::sensor_channels(rec), (std::vector<std::size_t>{0}));
    ASSERT_FALSE(notes.empty());
    EXPECT_NE(notes[0].find("no single shaft"), std::string::npos) << notes[0];
  }
  // Named like a tacho, at a rate the description's stale speed does not explain (the box at
  // 30 rpm, the tacho at 2000 rpm): the tacho is the measurement, used with a warning.
  {
    const diag::Gearbox stale = three_shaft().with_input_speed_rpm(30);
    auto rec = measured("tacho", pulses(n, fs, 2000.0 / 60));
    const auto notes = diag::infer_tachos(rec, &stale);
    ASSERT_EQ(rec.tachos.size(), 1u);
    EXPECT_EQ(rec.tachos[0].shaft, "input");
    EXPECT_EQ(rec.tachos[0].ppr, 1);
    ASSERT_FALSE(notes.empty());
    EXPECT_TRUE(notes[0].starts_with("warning: channel 'tacho'")) << notes[0];
    EXPECT_NE(notes[0].find("30 rpm"), std::string::npos) << notes[0];
  }
  // Stated roles are left alone; so is a channel the map described.
  {
    auto rec = measured("input", pulses(n, fs, f_in));
    rec.roles_stated = true;
    diag::infer_tachos(rec, &gb);
    EXPECT_TRUE(rec.tachos.empty());
    rec.roles_stated = false;
    diag::infer_tachos(rec, &gb, {"input"});
    EXPECT_TRUE(rec.tachos.empty());
  }
  // An analog speed channel named rpm is a speed, not vibration.
  {
    std::vector<double> rpm(n, 1500.0);
    for (std::size_t i = 0; i < n; ++i) rpm[i] += 3 * std::sin(static_cast<double>(i) * 1e-3);
    auto rec = measured("motor_rpm", rpm);
    diag::infer_tachos(rec, &gb);
    EXPECT_EQ(rec.signals[1].role, diag::Role::kSpeed);
    EXPECT_EQ(diag::sensor_channels(rec).size(), 1u);
  }
}

}  // namespace

// order_statistics (the levels of pulse_train_rate_hz) is exact: the same values as nth_element on
// a copy, for noise, ties, spikes, a two-level train, spans too small or too large for the
// histogram's bin width, and the extreme ranks.
TEST(Channels, OrderStatisticsAreThoseOfNthElement) {
  std::vector<std::vector<double>> inputs;
  inputs.push_back(noise(10007, 5));
  std::vector<double> spiky = noise(5000, 6);
  spiky[17] = 1e300;
  spiky[400] = -1e299;
  inputs.push_back(spiky);
  std::vector<double> ties(3001);
  for (std::size_t i = 0; i < ties.size(); ++i) ties[i] = static_cast<double>(i % 3);
  inputs.push_back(ties);
  inputs.push_back(pulses(20000, 10000.0, 33.3));
  inputs.push_back({5e-324, 0.0, 1e-323, 5e-324, 0.0, -5e-324});
  inputs.push_back({-1e308, 1e308, 0.0, 1.0, -1.0});
  inputs.push_back(std::vector<double>(64, 2.5));
  for (std::size_t c = 0; c < inputs.size(); ++c) {
    const std::vector<double>& x = inputs[c];
    const std::size_t n = x.size();
    for (const std::array<std::size_t, 2> k :
         {std::array<std::size_t, 2>{0, n - 1},
          {static_cast<std::size_t>(0.002 * (n - 1)), static_cast<std::size_t>(0.998 * (n - 1))},
          {n / 2, n / 3}}) {
      const std::array<double, 2> got = diag::order_statistics(x, k);
      for (int j = 0; j < 2; ++j) {
        std::vector<double> sorted(x);
        std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k[j]),
                         sorted.end());
        EXPECT_EQ(got[j], sorted[k[j]]) << "input " << c << ", rank " << k[j];
      }
    }
  }
  EXPECT_THROW(diag::order_statistics(inputs[0], {0, inputs[0].size()}), std::invalid_argument);
}
