// A recording: what a rig (or the simulator) recorded, in memory. Signals are uniformly sampled
// channels; tachometers are pulse channels per shaft. The on-disk form is HDF5 (io/hdf5.hpp).
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

struct Signal {
  std::string name;          // channel name, unique in a recording; no '/'
  double fs_hz = 0.0;        // sampling rate [Hz], > 0
  std::string unit;          // unit symbol ("m/s^2", "rad", "g", ...); empty when unknown
  Direction direction = Direction::kUnspecified;
  std::string location;      // bearing or shaft the sensor sits on; empty when unknown
  std::vector<double> samples;

  double duration_s() const { return fs_hz > 0 ? samples.size() / fs_hz : 0.0; }
};

struct Recording {
  std::vector<Signal> signals;   // /signals/<name>
  std::vector<Signal> tachos;    // /tacho/<shaft>: pulse trains, location = shaft name
  std::string gearbox_json;      // /gearbox: the description as given; empty when unknown
  std::string truth_json;        // /truth: ground truth of a simulated recording; empty otherwise
  std::map<std::string, std::string> metadata;  // extra root attributes (source file, rpm, ...)

  const Signal* find(std::string_view name) const;  // nullptr when absent
  // Throws InputError naming `where` and the channel, listing the channels that exist.
  const Signal& require(std::string_view name, const std::string& where) const;
};

// Checks a signal before it is written or analysed: name, fs > 0, finite samples, non-empty.
// Throws InputError naming `where`, the channel and the first bad sample index.
void validate(const Signal& s, const std::string& where);

}  // namespace diag
