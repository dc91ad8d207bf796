#include "diag/io/recording_frames.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace diag {

namespace {

Signal slice(const Signal& s, double t0, double t1) {
  Signal out;
  out.identity() = s.identity();
  const std::size_t first = samples_within(s.samples.size(), s.fs_hz, t0);
  const std::size_t end = std::max(first, samples_within(s.samples.size(), s.fs_hz, t1));
  out.samples.assign(s.samples.begin() + static_cast<std::ptrdiff_t>(first),
                     s.samples.begin() + static_cast<std::ptrdiff_t>(end));
  return out;
}

class MemoryFrames : public FrameSource {
 public:
  explicit MemoryFrames(std::shared_ptr<const Recording> rec) : rec_(std::move(rec)) {}
  std::vector<ChannelExtent> extents() const override {
    std::vector<ChannelExtent> out;
    for (const auto* group : {&rec_->signals, &rec_->tachos}) {
      for (const Signal& s : *group) out.push_back({s.samples.size(), s.fs_hz});
    }
    return out;
  }
  Recording frame(double t0_s, double t1_s) const override {
    Recording out;
    out.gearbox_json = rec_->gearbox_json;
    out.truth_json = rec_->truth_json;
    out.metadata = rec_->metadata;
    out.speed_rpm = rec_->speed_rpm;
    out.roles_stated = rec_->roles_stated;
    out.notes = rec_->notes;
    for (const Signal& s : rec_->signals) out.signals.push_back(slice(s, t0_s, t1_s));
    for (const Signal& s : rec_->tachos) out.tachos.push_back(slice(s, t0_s, t1_s));
    return out;
  }

 private:
  std::shared_ptr<const Recording> rec_;
};

class Hdf5Frames : public FrameSource {
 public:
  explicit Hdf5Frames(std::shared_ptr<const RecordingReader> reader) : reader_(std::move(reader)) {}
  std::vector<ChannelExtent> extents() const override {
    std::vector<ChannelExtent> out;
    for (const ChannelInfo& c : reader_->channels()) out.push_back({c.length, c.fs_hz});
    return out;
  }
  Recording frame(double t0_s, double t1_s) const override {
    return read_recording_span(*reader_, t0_s, t1_s);
  }

 private:
  std::shared_ptr<const RecordingReader> reader_;
};

}  // namespace

RecordingFrames::RecordingFrames(std::shared_ptr<const FrameSource> source)
    : source_(std::move(source)), extents_(source_->extents()) {}

RecordingFrames::RecordingFrames(std::shared_ptr<const Recording> recording)
    : RecordingFrames(std::make_shared<const MemoryFrames>(std::move(recording))) {}

RecordingFrames::RecordingFrames(std::shared_ptr<const RecordingReader> reader)
    : RecordingFrames(std::make_shared<const Hdf5Frames>(std::move(reader))) {}

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

}  // namespace diag
