// analyze's scalar features by name, for trending (features(), analyze.hpp).
#include <cmath>

#include "stages.hpp"

namespace detect {

std::map<std::string, double> features(const AnalysisResult& r) {
  std::map<std::string, double> f;
  auto put = [&f](const std::string& k, double v) {
    if (std::isfinite(v)) f[k] = v;
  };
  for (const auto& c : r.channels) {
    const std::string p = c.name + "/";
    put(p + "rms", c.time.rms);
    put(p + "peak", c.time.peak);
    put(p + "crest_factor", c.time.crest_factor);
    put(p + "kurtosis", c.time.kurtosis);
    put(p + "skewness", c.time.skewness);
    for (const auto& m : c.meshes) {
      for (const auto& l : m.sidebands.mesh) {
        if (l.valid) {
          put(p + "mesh/" + m.name + "/h" + std::to_string(&l - m.sidebands.mesh.data() + 1) +
                  "_amplitude",
              l.amplitude);
        }
      }
    }
    for (const auto& t : c.tsa) {
      for (const auto& g : t.gears) {
        const std::string q = p + "tsa/" + t.shaft + "/" + g.gear + "/";
        const GearIndicators& i = g.indicators;
        put(q + "fm0", i.fm0);
        put(q + "fm4", i.fm4);
        put(q + "m6a", i.m6a);
        put(q + "m8a", i.m8a);
        put(q + "na4", i.na4);
        put(q + "er", i.er);
        put(q + "ser", i.ser);
        put(q + "slf", i.slf);
        put(q + "si", i.si);
      }
    }
  }
  for (const auto& t : r.two_direction) {
    put("two_direction/" + t.location + "/" + t.mesh + "/normal_to_along_db",
        t.comparison.normal_to_along_db);
  }
  if (r.gear_damage) {
    for (const auto& s : r.gear_damage->shafts) {
      const std::string q = "gear_damage/" + s.shaft + "/";
      put(q + "score", s.score);
      put(q + "snr", s.snr);
      put(q + "level", s.level);
    }
  }
  return f;
}

}  // namespace detect
