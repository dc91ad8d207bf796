// Life histories (`geardiag dataset` with a `life` block; docs/cli/dataset.md, "Life histories"):
// one gearbox's life as dated recordings. Every class's `recordings` count histories; each
// history is `life.recordings` recordings of the same gears (one gearbox, accuracy grade, runout,
// pitch errors and operating point, drawn once per history), each with its own sensor noise and a
// small jitter of speed and torque, taken `interval_h` apart. A class's faults start at a drawn
// step (`onset`) and grow linearly with the step: each size range [lo, hi] of the fault (crack
// depth_mm, chip size_mm, spall length_mm and depth_um, wear depth_um, a bearing defect's
// amplitude_m_per_s2) is lo at the onset and hi at the history's last recording. The first
// `reference` recordings of every history are healthy: the reference a monitoring system learns the
// machine from.
//
// Spec block (JSON, unknown fields refused):
//   life {recordings      integer >= 2, per history
//         reference       integer in [1, recordings - 1], default min(3, recordings - 1)
//         onset           integer or [lo, hi] within [reference, recordings - 1]; default the
//                         whole span
//         start           "YYYY-MM-DDTHH:MM:SS", the first recording's time (default
//                         2026-01-05T08:00:00)
//         interval_h      hours between recordings, > 0 (default 24)
//         speed_jitter, torque_jitter   relative, in [0, 0.5]: each recording's speed and
//                         torque are the history's times 1 + u, u uniform in +-jitter (default 0)}
// Recording k is step k mod recordings of history k / recordings; its id ends in
// "-life<history>" (so `recordings/*-life3.h5` is one history) and its file holds its time as the
// `timestamp` attribute, which `geardiag batch --healthy-first` orders by.
// Draws: the history's parameters come from a stream seeded from (seed, history), the same for
// every step; the step's jitter and noise seed from the recording's own stream (seed, k).
#pragma once

#include "dataset_spec.hpp"

namespace geardiag {

// Parses the spec's `life` block (f is the spec's top level) into s.life, and makes the class
// counts histories (s.total recordings). Throws diag::InputError naming the field.
void parse_life(const diag::Fields& f, DatasetSpec& s);

// The history and step of recording k, and the stream its history's parameters are drawn from.
struct LifeStep {
  std::size_t history = 0;
  int step = 0;
};
LifeStep life_step(const LifeSettings& life, std::size_t k);
DrawStream history_stream(std::uint64_t seed, std::size_t history);

// Recording r's life on top of its history's draws (r's operating point and faults as drawn for
// the history, r.history and r.step set): its time, the jitter of speed and torque, its noise
// seed, the fault's onset, and the faults' sizes at this step (none before the onset). `cls` is
// the class the faults were drawn for.
void live(const DatasetSpec& s, const DatasetClass& cls, DrawnRecording& r);

}  // namespace geardiag
