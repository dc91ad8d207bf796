// The channel contract: what each channel of a recording is, and which channels serve a shaft,
// a bearing or a mesh. One place, used by the simulator (which writes roles), the importers and
// every detector (which read them); no detector parses a channel name.
//
// Where roles come from, in order:
//  1. A geardiag recording of format 2 or the simulator: stored with every channel.
//  2. A channel map (`--channels MAP.json`) and `--tacho CHANNEL=SHAFT[:PPR]` (apply_channel_map).
//  3. Inference, only for channels nobody described (Recording::roles_stated false: imported
//     files and format-1 files without directions; infer_tachos): a channel whose name contains
//     "tach", "key" or "rpm", or whose samples are a two-level pulse train, is a tacho when its
//     pulse rate is consistent with the description (a shaft's nominal speed times a whole number
//     of pulses per revolution, within +-20 %); the note says so. A channel named "rpm" that is not
//     a pulse train is a speed signal. Neither is ever analysed as vibration.
//  4. Format-1 files: infer_format1_roles (hdf5.hpp says how).
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "diag/gearbox/gearbox.hpp"
#include "diag/io/recording.hpp"

namespace diag {

// "<driver>_<driven>": the one name of a mesh, in channel names, Signal::mesh and every report.
std::string mesh_name(const Gearbox& gb, int mesh);
// The mesh index of a name made by mesh_name; -1 when the gearbox has no such mesh.
int mesh_index(const Gearbox& gb, const std::string& name);

// The channels that stand for the machine's vibration, as indices into rec.signals: role
// vibration. The simulator's internal quantities (mesh force, deflection, contact state, angles)
// have other roles: analysed and shown, they do not vote in findings nor enter a baseline.
std::vector<std::size_t> sensor_channels(const Recording& rec);

// The vibration channels on a shaft, as indices into rec.signals: Signal::shaft equal to the
// shaft, or a location naming a bearing of the description on that shaft. Empty when none (then
// every sensor channel is a casing sensor hearing all shafts: the caller decides).
std::vector<std::size_t> shaft_sensors(const Recording& rec, const Gearbox& gb,
                                       const std::string& shaft);

// The meshes whose line of action a sensor follows: its Signal::mesh when the gearbox has it;
// else every mesh with a gear on the sensor's shaft (Signal::shaft, or the shaft of the bearing in
// its location); else none.
std::vector<int> sensor_meshes(const Signal& s, const Gearbox& gb);

// The shaft a sensor sits on: Signal::shaft when set, else the shaft of the description's bearing
// named by its location; -1 when unknown.
int sensor_shaft(const Signal& s, const Gearbox& gb);

// The tacho of a shaft: the first of rec.tachos whose Signal::shaft (when empty: location) is
// `shaft`; nullptr when none.
const Signal* shaft_tacho(const Recording& rec, const std::string& shaft);

// Pulses per revolution of a tacho: Signal::ppr, at least 1.
int pulses_per_rev(const Signal& tacho);

// Format-1 recordings (no role attributes): roles from directions, units and the simulator's
// documented names (hdf5.hpp); adds a note to rec.notes. Used by read_recording.
void infer_format1_roles(Recording& rec);

// ---- channel maps ----
// {"channels": [{"name": "acc1", "role": "vibration", "unit": "m/s^2", "direction": "vertical",
//                "location": "drive_end", "shaft": "input", "mesh": "z1_z2"},
//               {"name": "key", "role": "tacho", "shaft": "input", "ppr": 1}]}
// Only "name" is required; fields left out keep the channel's own. Unknown fields are refused.
struct ChannelMapEntry {
  std::string name;
  std::optional<Role> role;
  std::optional<std::string> unit, location, shaft, mesh;
  std::optional<Direction> direction;
  std::optional<int> ppr;
};
struct ChannelMap {
  std::vector<ChannelMapEntry> channels;
  bool empty() const { return channels.empty(); }
};

// Throws InputError naming `where` (the file) and the field.
ChannelMap parse_channel_map(const nlohmann::json& j, const std::string& where);
ChannelMap load_channel_map(const std::filesystem::path& path);
// "CHANNEL=SHAFT[:PPR]" (PPR >= 1, default 1) as a map entry with role tacho. Throws InputError
// naming `option` ("--tacho").
ChannelMapEntry parse_tacho_option(const std::string& text, const std::string& option);

// Applies the map: each entry must name a channel of the recording (signals or tachos); a channel
// given role tacho moves to rec.tachos, a tacho given another role moves to rec.signals. With a
// gearbox, shafts and meshes must be the description's. A tacho must end with ppr >= 1 and a
// shaft. Throws InputError naming `where` and the entry.
void apply_channel_map(Recording& rec, const ChannelMap& map, const Gearbox* gb,
                       const std::string& where);

// Two-level pulse trains: with the levels at the 0.2 and 99.8 percentiles, at least 95 % of the
// samples lie within 20 % of their distance of one of them, both levels hold at least 0.2 % of
// the samples, and the train has at least 3 rising edges (Gaussian noise: 8 % near the levels; a
// sine: 59 %). Returns the rising edges per second (threshold halfway,
// 10 % hysteresis), or nullopt when `x` is not such a train.
std::optional<double> pulse_train_rate_hz(const std::vector<double>& x, double fs_hz);

// The k[0]-th and k[1]-th smallest of x (0-based ranks; what std::nth_element on a copy gives), in
// two passes over x: a 4096-bin histogram on [min, max] finds the bin holding each rank, and
// nth_element runs on that bin's samples only. Throws std::invalid_argument for a rank past the
// end.
std::array<double, 2> order_statistics(std::span<const double> x, std::array<std::size_t, 2> k);

// Inference (step 3 above) for a recording whose roles nobody stated (rec.roles_stated false),
// skipping the channels named in `described` (the channel map's). Moves the tachos found to
// rec.tachos and returns one note per decision.
std::vector<std::string> infer_tachos(Recording& rec, const Gearbox* gb,
                                      const std::vector<std::string>& described = {});

}  // namespace diag
