#include "diag/io/recording_frames.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace diag {

namespace {

// The index of the first sample at or after t [s] (floor(t fs), within [0, length]).
std::size_t sample_at(const Signal& s, double t) {
  if (!std::isfinite(t)) return s.samples.size();
  const double n = std::floor(t * s.fs_hz);
  if (n <= 0) return 0;
  return n >= static_cast<double>(s.samples.size()) ? s.samples.size()
                                                    : static_cast<std::size_t>(n);
}

Signal slice(const Signal& s, double t0, double t1) {
  Signal out;
  out.name = s.name;
  out.fs_hz = s.fs_hz;
  out.unit = s.unit;
  out.direction = s.direction;
  out.location = s.location;
  out.role = s.role;
  out.shaft = s.shaft;
  out.mesh = s.mesh;
  out.ppr = s.ppr;
  const std::size_t first = sample_at(s, t0);
  const std::size_t end = std::max(first, sample_at(s, t1));
  out.samples.assign(s.samples.begin() + static_cast<std::ptrdiff_t>(first),
                     s.samples.begin() + static_cast<std::ptrdiff_t>(end));
  return out;
}

}  // namespace

RecordingFrames::RecordingFrames(std::shared_ptr<const Recording> recording)
    : recording_(std::move(recording)) {
  for (const auto* group : {&recording_->signals, &recording_->tachos}) {
    for (const Signal& s : *group) extents_.push_back({s.samples.size(), s.fs_hz});
  }
}

RecordingFrames::RecordingFrames(std::shared_ptr<const RecordingReader> reader)
    : reader_(std::move(reader)) {
  for (const ChannelInfo& c : reader_->channels()) extents_.push_back({c.length, c.fs_hz});
}

double RecordingFrames::duration_s() const {
  double d = 0;
  for (const ChannelExtent& c : extents_) {
    if (c.fs_hz > 0) d = std::max(d, static_cast<double>(c.length) / c.fs_hz);
  }
  return d;
}

double RecordingFrames::frame_seconds(const ReadLimits& limits) const {
  return std::min(duration_s(), seconds_within_limits(extents_, limits));
}

Recording RecordingFrames::frame(double t0_s, double t1_s) const {
  if (reader_) return read_recording_span(*reader_, t0_s, t1_s);
  Recording out;
  out.gearbox_json = recording_->gearbox_json;
  out.truth_json = recording_->truth_json;
  out.metadata = recording_->metadata;
  out.speed_rpm = recording_->speed_rpm;
  out.roles_stated = recording_->roles_stated;
  out.notes = recording_->notes;
  for (const Signal& s : recording_->signals) out.signals.push_back(slice(s, t0_s, t1_s));
  for (const Signal& s : recording_->tachos) out.tachos.push_back(slice(s, t0_s, t1_s));
  return out;
}

}  // namespace diag
