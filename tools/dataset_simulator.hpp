// The simulators `geardiag dataset` drives, behind one interface: the dynamic model
// (dataset_spec.cpp), the kinematic model and the face-gear pair (dataset_modes.cpp). A spec's
// `simulator` field names one (dataset_simulator); every step of the command (reading the spec,
// drawing a recording, simulating it, its manifest row) asks the named one, so that a simulator
// is one class and one row of the table in dataset_modes.cpp.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "dataset_spec.hpp"
#include "diag/io/recording.hpp"

namespace geardiag {

class DatasetSimulator {
 public:
  virtual ~DatasetSimulator() = default;

  // The name in the spec's and the manifest's `simulator` field.
  virtual const char* name() const = 0;

  // Parses and checks the spec's fields into s (s.file, s.json and s.simulator are set). Throws
  // diag::InputError naming the field before anything is written.
  virtual void load(DatasetSpec& s) const = 0;

  // Recording r's draws from rng (r.index, r.id and r.cls are set; rng is seeded from
  // (seed, index), so the draws depend on nothing else).
  virtual void draw(const DatasetSpec& s, const DatasetClass& cls, DrawStream& rng,
                    DrawnRecording& r) const = 0;

  // The manifest's columns, in order, and recording r's row (one value per column, null where a
  // column does not apply).
  virtual std::vector<std::string> manifest_columns(const DatasetSpec& s) const = 0;
  virtual nlohmann::json manifest_row(const DatasetSpec& s, const DrawnRecording& r) const = 0;

  // Simulates one drawn recording (its /truth is the simulator's); appends the simulator's
  // warnings to `warnings`.
  virtual diag::Recording simulate(const DatasetSpec& s, const DrawnRecording& r,
                                   std::vector<std::string>& warnings) const = 0;

  // The description recording r was simulated from, as its truth's dataset.scenario keeps it.
  virtual const nlohmann::json& model(const DrawnRecording& r) const = 0;

  // Whether some manifest columns are the simulation's outcome (then filled by add_outcomes from
  // the recording's truth, and the manifest is read back from the files' truth).
  virtual bool has_outcomes() const { return false; }
  virtual void add_outcomes(const nlohmann::json& truth, nlohmann::json& row) const {
    (void)truth;
    (void)row;
  }
};

// The simulator called `name`, or nullptr when there is none.
const DatasetSimulator* find_dataset_simulator(std::string_view name);

// The simulator of a loaded spec (s.simulator).
const DatasetSimulator& simulator_of(const DatasetSpec& s);

// The name of the simulator a spec asks for: its `simulator` field, else "face_gear" when its
// first gearbox is a face-gear description, else "dynamic". Throws diag::InputError for a
// `simulator` that names none.
std::string dataset_simulator(const nlohmann::json& spec, const std::filesystem::path& file);

// The table's rows.
const DatasetSimulator& dynamic_dataset_simulator();    // dataset_spec.cpp
const DatasetSimulator& kinematic_dataset_simulator();  // dataset_modes.cpp
const DatasetSimulator& face_gear_dataset_simulator();  // dataset_modes.cpp

}  // namespace geardiag
