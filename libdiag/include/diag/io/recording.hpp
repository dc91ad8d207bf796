// A recording: what a rig (or the simulator) recorded, in memory. Signals are uniformly sampled
// channels; tachometers are pulse channels per shaft. The on-disk form is HDF5 (io/hdf5.hpp).
// Every channel says what it is (ChannelIdentity: role, shaft, mesh, ppr): the channel contract.
// Which channels are a shaft's sensors or tacho is answered in one place, io/channels.hpp; no
// detector parses a channel name.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace diag {

// Sensing direction of a channel (the `direction` attribute in HDF5).
enum class Direction {
  kUnspecified,  // "" : not known (imported data)
  kAlongLoa,     // "along_loa"  : along a mesh's line of action
  kNormalLoa,    // "normal_loa" : normal to a mesh's line of action
  kHorizontal,   // "horizontal" : fixed frame
  kVertical,     // "vertical"   : fixed frame
  kAngle,        // "angle"      : a shaft angle (rad) or transmission error
  kTacho,        // "tacho"      : tachometer pulse train
};
std::string_view to_string(Direction d);
// Throws InputError for an unknown name.
Direction direction_from_string(std::string_view name);

// What a channel measures (the `role` attribute in HDF5).
enum class Role {
  kVibration,     // "vibration"    : a vibration sensor (acceleration, velocity, sound): analysed
  kTacho,         // "tacho"        : a tachometer / keyphasor pulse train (Signal::ppr pulses/rev)
  kAngle,         // "angle"        : a shaft angle or transmission error [rad]
  kSpeed,         // "speed"        : a shaft speed signal (rpm or Hz as its unit says)
  kForce,         // "force"        : a force (the simulator's mesh force and friction) [N]
  kDisplacement,  // "displacement" : a displacement (the simulator's mesh deflection) [m]
  kOther,         // "other"        : anything else (contact state, a temperature, a trigger)
};
std::string_view to_string(Role r);
// Throws InputError for an unknown name.
Role role_from_string(std::string_view name);

// What a channel is: everything about it but its samples. A signal in memory (Signal), a channel
// of a file (ChannelInfo) and a channel's analysis carry it whole, so that it is copied in one
// assignment and a new field reaches every one of them.
struct ChannelIdentity {
  std::string name;    // channel name, unique in a recording; no '/'
  double fs_hz = 0.0;  // sampling rate [Hz], > 0
  std::string unit;    // unit symbol ("m/s^2", "rad", "g", ...); empty when unknown
  Direction direction = Direction::kUnspecified;
  std::string location;  // bearing or shaft the sensor sits on; empty when unknown
  Role role = Role::kVibration;
  std::string shaft;  // the shaft a sensor sits on or a tacho or angle belongs to; empty: unknown
  std::string mesh;   // the mesh (mesh_name(), "<driver>_<driven>") whose line of action an
                      // along/normal-LOA sensor follows, or a mesh quantity's mesh; empty: none
  int ppr = 0;        // tachos: pulses per shaft revolution, >= 1; 0 for every other role

  const ChannelIdentity& identity() const { return *this; }
  ChannelIdentity& identity() { return *this; }
};

struct Signal : ChannelIdentity {
  std::vector<double> samples;

  double duration_s() const { return fs_hz > 0 ? samples.size() / fs_hz : 0.0; }
};

struct Recording {
  std::vector<Signal> signals;  // /signals/<name>
  std::vector<Signal> tachos;   // /tacho/<shaft>: pulse trains, location = shaft name
  std::string gearbox_json;     // /gearbox: the description as given; empty when unknown
  std::string truth_json;       // /truth: ground truth of a simulated recording; empty otherwise
  std::map<std::string, std::string> metadata;  // extra root attributes (source file, rpm, ...)
  // The input shaft's speed recorded with the data [rpm] (root attribute `input_speed_rpm`;
  // imported from e.g. CWRU's X105RPM); 0 when unknown. Analysis prefers it to a description's
  // nominal.
  double speed_rpm = 0.0;
  // How the roles were obtained, said by analyze and info: empty when they were stored (format 2)
  // or set by the simulator; else e.g. "format-1 file: roles inferred from directions".
  std::vector<std::string> notes;
  // True when every channel's role was stated (a format-2 file, the simulator, a channel map);
  // false for imported measurements and format-1 files: tacho inference may then run
  // (channels.hpp).
  bool roles_stated = true;

  const Signal* find(std::string_view name) const;  // nullptr when absent
  // Throws InputError naming `where` and the channel, listing the channels that exist.
  const Signal& require(std::string_view name, const std::string& where) const;
};

// Checks a signal before it is written or analysed: name, fs > 0, finite samples, non-empty.
// Throws InputError naming `where`, the channel and the first bad sample index.
void validate(const Signal& s, const std::string& where);

}  // namespace diag
