// analyze's JSON report writer (to_json, report.hpp; the keys are the README's).
#include <cmath>
#include <nlohmann/json.hpp>

#include "detect/bearing/bearing_diagnosis.hpp"
#include "detect/gear/gear_damage.hpp"
#include "report/report.hpp"

namespace report {

using namespace detect;

namespace {

// Points of the speed trace in the JSON (a tacho gives one estimate per revolution).
constexpr std::size_t kSpeedTracePoints = 200;

// One fault vocabulary in the report (diag/faults/fault_kind.hpp), "none" for no fault.
std::string fault_name(BearingFault f) { return to_string(f); }

nlohmann::json peaks_json(const std::vector<SpectralPeak>& p) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& k : p)
    a.push_back({{"frequency_hz", k.frequency_hz}, {"amplitude", k.amplitude}});
  return a;
}

const char* to_string(SidebandStatus s) {
  switch (s) {
    case SidebandStatus::kNoSidebands:
      return "no_sidebands";
    case SidebandStatus::kPointed:
      return "pointed";
    case SidebandStatus::kAmbiguous:
      return "ambiguous";
  }
  return "unknown";
}

// The reference shaft's speed: its source and range, and the speed over time in at most
// kSpeedTracePoints points (means over equal runs of the estimates: a tacho gives one per
// revolution).
nlohmann::json speed_json(const AnalysisSpeed& speed) {
  using nlohmann::json;
  json sp = {{"source", speed.source},
             {"reference_shaft", speed.reference_shaft},
             {"line", speed.line},
             {"nominal_rpm", speed.nominal_rpm},
             {"mean_rpm", speed.mean_rpm},
             {"min_rpm", speed.min_rpm},
             {"max_rpm", speed.max_rpm},
             {"stationary", speed.stationary},
             {"spectra_domain", speed.spectra_domain}};
  if (std::isfinite(speed.phase_jitter_deg)) {
    sp["phase_jitter_deg"] = speed.phase_jitter_deg;
    sp["angle_uncertainty_deg"] = speed.angle_uncertainty_deg;
  }
  const std::size_t n = speed.time_s.size();
  if (n > 0) {
    const std::size_t buckets = std::min(n, kSpeedTracePoints);
    json t = json::array(), v = json::array();
    for (std::size_t b = 0; b < buckets; ++b) {
      const std::size_t i0 = b * n / buckets, i1 = (b + 1) * n / buckets;
      double st = 0, sv = 0;
      for (std::size_t i = i0; i < i1; ++i) st += speed.time_s[i], sv += speed.speed_rpm[i];
      t.push_back(st / static_cast<double>(i1 - i0));
      v.push_back(sv / static_cast<double>(i1 - i0));
    }
    sp["time_s"] = std::move(t);
    sp["rpm"] = std::move(v);
  }
  return sp;
}

// Each mesh's harmonics and the sideband families of its candidate shafts.
nlohmann::json meshes_json(const ChannelAnalysis& c) {
  using nlohmann::json;
  json meshes = json::array();
  for (const auto& m : c.meshes) {
    json h = json::array();
    int k = 1;
    for (const auto& l : m.sidebands.mesh) {
      h.push_back({{"harmonic", k++},
                   {"frequency_hz", l.frequency_hz},
                   {"amplitude", l.amplitude},
                   {"prominence_db", l.prominence_db},
                   {"valid", l.valid}});
    }
    json shafts = json::array();
    for (const auto& s : m.sidebands.shafts) {
      shafts.push_back({{"shaft", s.name},
                        {"frequency_hz", s.frequency_hz},
                        {"detected", s.detected},
                        {"score_db", s.score_db},
                        {"passes", s.passes}});
    }
    const bool pointed = m.sidebands.status == SidebandStatus::kPointed;
    meshes.push_back(
        {{"mesh", m.name},
         {"frequency_hz", m.mesh_hz},
         {"harmonics", h},
         {"sidebands",
          {{"status", to_string(m.sidebands.status)},
           {"pointed_shaft",
            pointed ? json(m.sidebands.shafts[static_cast<std::size_t>(m.sidebands.pointed)].name)
                    : json(nullptr)},
           {"shafts", shafts}}}});
  }
  return meshes;
}

// The TSA of each shaft with gears and the gears' metrics.
nlohmann::json tsa_json(const ChannelAnalysis& c) {
  using nlohmann::json;
  json tsa = json::array();
  for (const auto& t : c.tsa) {
    json gears = json::array();
    for (const auto& g : t.gears) {
      const GearIndicators& i = g.indicators;
      gears.push_back({{"gear", g.gear},
                       {"teeth", g.teeth},
                       {"rms", i.rms},
                       {"peak", i.peak},
                       {"crest_factor", i.crest_factor},
                       {"kurtosis", i.kurtosis},
                       {"fm0", i.fm0},
                       {"fm4", i.fm4},
                       {"m6a", i.m6a},
                       {"m8a", i.m8a},
                       {"na4", i.na4},
                       {"er", i.er},
                       {"ser", i.ser},
                       {"slf", i.slf},
                       {"si", i.si}});
    }
    tsa.push_back({{"shaft", t.shaft},
                   {"computed", t.computed},
                   {"note", t.note},
                   {"revolutions", t.revolutions},
                   {"samples_per_rev", t.samples_per_rev},
                   {"gears", gears}});
  }
  return tsa;
}

// The decision's evidence per family: each harmonic's prominence (0 where not measurable), the
// sidebands and modulation lines seen, and whether another family explains it.
nlohmann::json families_json(const BearingDecision& d) {
  using nlohmann::json;
  json fams = json::array();
  for (const auto& fam : d.families) {
    json line_db = json::array();
    for (const auto& m : fam.lines) line_db.push_back(m.valid ? m.prominence_db : 0.0);
    fams.push_back({{"fault", fault_name(fam.fault)},
                    {"fundamental_hz", fam.fundamental_hz},
                    {"detected", fam.detected},
                    {"line_db", line_db},
                    {"sidebands_detected", fam.sidebands_detected},
                    {"modulation_lines", fam.modulation_lines},
                    {"explained", fam.explained},
                    {"score_db", fam.score_db},
                    {"passes", fam.passes}});
  }
  return fams;
}

// Each bearing the channel sees: its fault frequencies, fault bands and the decision.
nlohmann::json bearings_json(const ChannelAnalysis& c) {
  using nlohmann::json;
  json bearings = json::array();
  for (const auto& b : c.bearings) {
    const BearingFrequencies& f = b.frequencies;
    json bands = json::array();
    for (std::size_t k = 0; k < b.bands.size(); ++k) {
      const BandMetrics& m = b.metrics.bands[k];
      bands.push_back({{"label", b.bands[k].label},
                       {"centre_hz", b.bands[k].centre_hz},
                       {"low_hz", b.bands[k].low_hz},
                       {"high_hz", b.bands[k].high_hz},
                       {"peak", m.peak_value},
                       {"peak_frequency_hz", m.peak_frequency_hz},
                       {"energy", m.energy},
                       {"energy_fraction", m.energy_fraction}});
    }
    bearings.push_back({{"bearing", b.bearing},
                        {"shaft", b.shaft},
                        {"frequencies",
                         {{"shaft_hz", f.shaft_hz},
                          {"ftf_hz", f.ftf_hz},
                          {"bpfo_hz", f.bpfo_hz},
                          {"bpfi_hz", f.bpfi_hz},
                          {"bsf_hz", f.bsf_hz},
                          {"ball_fault_hz", f.ball_fault_hz}}},
                        {"bands", bands},
                        {"decision",
                         {{"diagnosed", b.diagnosed},
                          {"status", to_string(b.diagnosis.status)},
                          {"fault", fault_name(b.diagnosis.fault)},
                          {"note", b.diagnosis.note},
                          {"band_centre_hz", b.band_centre_hz},
                          {"band_width_hz", b.band_width_hz},
                          {"families", families_json(b.diagnosis.band_decision)},
                          {"whole_band_families", families_json(b.diagnosis.whole_decision)}}}});
  }
  return bearings;
}

// One channel: what it is, its indicators, spectra and envelope summaries, meshes, TSA,
// bearings and notes.
nlohmann::json channel_json(const ChannelAnalysis& c) {
  using nlohmann::json;
  json cj{{"name", c.name},
          {"unit", c.unit},
          {"direction", std::string(diag::to_string(c.direction))},
          {"location", c.location},
          {"role", std::string(diag::to_string(c.role))},
          {"shaft", c.shaft},
          {"mesh", c.mesh},
          {"fs_hz", c.fs_hz},
          {"samples", c.samples},
          {"vibration", c.vibration},
          {"sensor", c.sensor},
          {"indicators",
           {{"rms", c.time.rms},
            {"peak", c.time.peak},
            {"crest_factor", c.time.crest_factor},
            {"kurtosis", c.time.kurtosis},
            {"skewness", c.time.skewness}}}};
  if (c.vibration && c.spectrum_resolution_hz > 0) {  // spectra computed (traces or not)
    cj["spectrum"] = {{"resolution_hz", c.spectrum_resolution_hz},
                      {"enbw_hz", c.spectrum_enbw_hz},
                      {"peaks", peaks_json(c.spectrum_peaks)}};
    if (c.spectrum_parts > 1) cj["spectrum"]["parts"] = c.spectrum_parts;
    cj["psd"] = {{"resolution_hz", c.psd_resolution_hz}, {"segments", c.psd_segments}};
  }
  if (c.sensor && c.spectrum_resolution_hz > 0) {  // envelope: vibration sensors (traces or not)
    cj["envelope"] = {{"band_low_hz", c.envelope_low_hz},
                      {"band_high_hz", c.envelope_high_hz},
                      {"kurtogram_level", c.kurtogram_level},
                      {"kurtogram_kurtosis", c.kurtogram_kurtosis},
                      {"peaks", peaks_json(c.envelope_peaks)}};
    if (c.envelope_parts > 1) cj["envelope"]["parts"] = c.envelope_parts;
  }
  cj["meshes"] = meshes_json(c);
  cj["tsa"] = tsa_json(c);
  cj["bearings"] = bearings_json(c);
  cj["notes"] = c.notes;
  return cj;
}

// The two-direction rows: the mesh-harmonic energies along and normal to the line of action.
nlohmann::json two_direction_json(const AnalysisResult& r) {
  using nlohmann::json;
  json rows = json::array();
  for (const auto& t : r.two_direction) {
    json h = json::array();
    for (const auto& e : t.comparison.harmonics) {
      h.push_back({{"harmonic", e.harmonic},
                   {"frequency_hz", e.frequency_hz},
                   {"along", e.along},
                   {"normal", e.normal},
                   {"valid", e.valid}});
    }
    rows.push_back({{"location", t.location},
                    {"along_channel", t.along_channel},
                    {"normal_channel", t.normal_channel},
                    {"mesh", t.mesh},
                    {"mesh_hz", t.comparison.mesh_hz},
                    {"along_energy", t.comparison.along_energy},
                    {"normal_energy", t.comparison.normal_energy},
                    {"normal_to_along_db", t.comparison.normal_to_along_db},
                    {"harmonics", h}});
  }
  return rows;
}

// The baseline comparison's keys, at the top level (anomaly_score, alarm, ...) and under
// "baseline".
void add_baseline(const AnalysisBaseline& b, nlohmann::json& j) {
  using nlohmann::json;
  j["anomaly_score"] = b.anomaly_score;
  j["alarm"] = b.alarm;
  j["anomaly_threshold"] = b.threshold;
  j["baseline_deviations"] = json::array();
  for (const auto& d : b.deviations) {
    j["baseline_deviations"].push_back({{"feature", d.feature},
                                        {"value", d.value},
                                        {"baseline_centre", d.baseline_centre},
                                        {"baseline_spread", d.baseline_spread},
                                        {"z", d.z}});
  }
  j["baseline"] = {{"recordings", b.recordings},
                   {"samples", b.samples},
                   {"channels", b.channels},
                   {"notes", b.notes}};
  // The wear indicator per mesh (mesh_harmonic_growth.hpp); empty without a gearbox.
  json wear = json::array();
  for (const auto& w : b.wear) {
    json per = json::object();
    for (std::size_t c = 0; c < w.channels.size(); ++c) per[w.channels[c]] = w.channel_db[c];
    wear.push_back({{"mesh", w.mesh},
                    {"mesh_frequency_hz", w.mesh_hz},
                    {"baseline_mesh_frequency_hz", w.baseline_mesh_hz},
                    {"growth_db", w.growth_db},
                    {"threshold_db", w.threshold_db},
                    {"flagged", w.flagged},
                    {"channel_db", std::move(per)}});
  }
  j["baseline"]["wear"] = std::move(wear);
}

// What was examined and the frames of a whole-log analysis (analyze_file).
void add_coverage(const AnalysisResult& r, nlohmann::json& j) {
  using nlohmann::json;
  const AnalysisCoverage& c = *r.coverage;
  j["analysed_s"] = c.analysed_s;
  j["examined"] = {{"complete", c.complete()},
                   {"duration_s", c.duration_s},
                   {"analysed_s", c.analysed_s},
                   {"frames", c.frames},
                   {"frames_examined", c.frames_examined},
                   {"frame_s", c.frame_s},
                   {"detail_frame", c.detail_frame},
                   {"not_examined", c.not_examined}};
  json segments = json::array();
  for (const AnalysisSegment& s : r.segments) {
    json sj{{"start_s", s.start_s}, {"end_s", s.end_s}, {"verdict", s.verdict}};
    if (!s.reason.empty()) sj["reason"] = s.reason;
    if (!s.cut.empty()) sj["cut"] = s.cut;
    if (std::isfinite(s.speed_rpm)) {
      sj["speed_rpm"] = s.speed_rpm;
      sj["speed_source"] = s.speed_source;
    }
    sj["findings"] = s.findings;
    if (std::isfinite(s.anomaly_score)) sj["anomaly_score"] = s.anomaly_score;
    json ch = json::object();
    for (std::size_t i = 0; i < s.channels.size(); ++i) {
      const TimeIndicators& t = s.indicators[i];
      ch[s.channels[i]] = {{"rms", t.rms},
                           {"peak", t.peak},
                           {"crest_factor", t.crest_factor},
                           {"kurtosis", t.kurtosis},
                           {"skewness", t.skewness}};
    }
    sj["channels"] = std::move(ch);
    segments.push_back(std::move(sj));
  }
  j["segments"] = std::move(segments);
}

}  // namespace

nlohmann::json to_json(const AnalysisResult& r) {
  using nlohmann::json;
  json j;
  j["format"] = "geardiag-analysis";
  j["format_version"] = 1;
  j["gearbox"] = r.gearbox_name.empty() ? json(nullptr) : json(r.gearbox_name);
  j["input_shaft"] = r.input_shaft.empty() ? json(nullptr) : json(r.input_shaft);
  j["duration_s"] = r.duration_s;
  if (r.coverage) add_coverage(r, j);
  if (!r.timing_s.empty()) j["timing_s"] = r.timing_s;
  if (!r.speed.source.empty()) j["speed"] = speed_json(r.speed);
  j["shafts"] = json::array();
  for (const auto& s : r.shafts) {
    j["shafts"].push_back({{"shaft", s.shaft},
                           {"speed_hz", s.speed_hz},
                           {"speed_rpm", s.speed_hz * 60},
                           {"source", s.source},
                           {"tacho_repairs", s.tacho_repairs}});
  }
  j["meshes"] = json::array();
  for (const auto& m : r.meshes) {
    j["meshes"].push_back({{"mesh", m.name},
                           {"driver", m.driver},
                           {"driven", m.driven},
                           {"frequency_hz", m.frequency_hz}});
  }
  j["channels"] = json::array();
  for (const auto& c : r.channels) j["channels"].push_back(channel_json(c));
  j["two_direction"] = two_direction_json(r);
  if (r.gear_damage) {
    j["gear_damage"] = to_json(*r.gear_damage);
    j["gear_damage"]["angles"] = r.gear_damage_angles;
  }
  j["findings"] = json::array();
  for (const auto& f : r.findings) j["findings"].push_back(to_json(f));
  if (r.baseline) add_baseline(*r.baseline, j);
  j["notes"] = r.notes;
  nlohmann::json stages = nlohmann::json::array();
  for (const StageRun& st : r.stages) {
    nlohmann::json sj{{"stage", st.stage}, {"ran", st.ran}, {"skipped", st.skipped}};
    if (!st.why.empty()) sj["why"] = st.why;
    stages.push_back(std::move(sj));
  }
  j["stages"] = std::move(stages);
  return j;
}

}  // namespace report
