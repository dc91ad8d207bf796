#include "dataset_life.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "time_stamp.hpp"

namespace geardiag {

namespace {

// Salts the histories' streams apart from the recordings' (which are seeded from (seed, k)), and
// the onset's apart from the history's other draws.
constexpr std::uint64_t kHistorySalt = 0x4c49464548495354ULL;  // "LIFEHIST"
constexpr std::uint64_t kOnsetSalt = 0x4c4946454f4e5354ULL;    // "LIFEONST"

double round4(double x) { return std::round(x * 1e4) / 1e4; }

}  // namespace

void parse_life(const diag::Fields& top, DatasetSpec& s) {
  if (!top.has("life")) return;
  const diag::Fields f(
      top.raw("life"), top.where(), "life",
      {"recordings", "reference", "onset", "start", "interval_h", "speed_jitter", "torque_jitter"});
  LifeSettings life;
  life.recordings = f.integer("recordings");
  if (life.recordings < 2 || life.recordings > 100000) {
    f.fail("recordings", "must be in [2, 100000] (got " + std::to_string(life.recordings) + ")");
  }
  life.reference = std::min(3, life.recordings - 1);
  if (f.has("reference")) {
    life.reference = f.integer("reference");
    if (life.reference < 1 || life.reference > life.recordings - 1) {
      f.fail("reference", "must be in [1, recordings - 1 = " + std::to_string(life.recordings - 1) +
                              "]: at least one recording after the reference");
    }
  }
  life.onset = {life.reference, life.recordings - 1};
  if (f.has("onset")) {
    life.onset = parse_int_range(f, "onset", 0, 100000);
    if (life.onset.lo < life.reference || life.onset.hi > life.recordings - 1) {
      f.fail("onset", "must lie within [reference, recordings - 1] = [" +
                          std::to_string(life.reference) + ", " +
                          std::to_string(life.recordings - 1) +
                          "]: the reference recordings are healthy");
    }
  }
  life.start = f.has("start") ? f.str("start") : "2026-01-05T08:00:00";
  if (!std::isfinite(epoch_s(life.start)) || life.start.size() != 19 ||
      iso_time(static_cast<std::int64_t>(epoch_s(life.start))) != life.start) {
    f.fail("start", "'" + life.start + "' is not a date-time YYYY-MM-DDTHH:MM:SS");
  }
  life.interval_h = f.has("interval_h") ? f.positive("interval_h") : 24.0;
  if (life.interval_h > 1e6) f.fail("interval_h", "must be <= 1e6 h");
  // The dates must stay four-digit years, which the times sort by as text.
  if (epoch_s(life.start) + life.interval_h * 3600.0 * (life.recordings - 1) >
      epoch_s("9999-12-31T23:59:59")) {
    f.fail("interval_h", "the last recording would fall after the year 9999");
  }
  for (const char* key : {"speed_jitter", "torque_jitter"}) {
    double& v = std::string(key) == "speed_jitter" ? life.speed_jitter : life.torque_jitter;
    v = f.has(key) ? f.num(key) : 0.0;
    if (!(v >= 0 && v <= 0.5)) f.fail(key, "must be in [0, 0.5]");
  }
  const std::size_t histories = s.total;
  if (histories * static_cast<std::size_t>(life.recordings) > 100000000) {
    f.fail("recordings", "more than 1e8 recordings in all");
  }
  s.total = histories * static_cast<std::size_t>(life.recordings);
  s.life = life;
}

LifeStep life_step(const LifeSettings& life, std::size_t k) {
  const auto n = static_cast<std::size_t>(life.recordings);
  return {k / n, static_cast<int>(k % n)};
}

DrawStream history_stream(std::uint64_t seed, std::size_t history) {
  return DrawStream(seed ^ kHistorySalt, history);
}

void live(const DatasetSpec& s, const DatasetClass& cls, DrawnRecording& r) {
  const LifeSettings& life = *s.life;
  // The onset is the history's.
  DrawStream onset(s.seed ^ kOnsetSalt, static_cast<std::size_t>(r.history));
  r.onset = cls.faults.empty() ? -1 : onset.draw(life.onset);
  // The step's own draws.
  DrawStream rng(s.seed, r.index);
  const double du = 2 * rng.uniform() - 1, dt = 2 * rng.uniform() - 1;
  r.speed_rpm = round4(r.speed_rpm * (1 + life.speed_jitter * du));
  r.torque_nm = round4(r.torque_nm * (1 + life.torque_jitter * dt));
  r.noise_seed = rng.next() % 1000000000ULL;
  const double hours = life.interval_h * r.step;
  r.time = iso_time(static_cast<std::int64_t>(epoch_s(life.start)) +
                    static_cast<std::int64_t>(std::llround(hours * 3600)));
  if (r.onset < 0 || r.step < r.onset) {
    r.faults.clear();
    return;
  }
  // Linear growth from lo at the onset to hi at the last recording.
  const int span = life.recordings - 1 - r.onset;
  const double g = span > 0 ? static_cast<double>(r.step - r.onset) / span : 1.0;
  for (std::size_t i = 0; i < r.faults.size(); ++i) {
    const DatasetFault& f = cls.faults[i];
    DrawnFault& d = r.faults[i];
    if (d.type == "bearing") {
      d.amplitude = round4(f.amplitude.lo + g * (f.amplitude.hi - f.amplitude.lo));
      continue;
    }
    if (d.type != "missing" && d.type != "wear") {
      d.size_mm = round4(f.size_mm.lo + g * (f.size_mm.hi - f.size_mm.lo));
    }
    if (d.has_depth) d.depth_um = round4(f.depth_um.lo + g * (f.depth_um.hi - f.depth_um.lo));
  }
}

}  // namespace geardiag
