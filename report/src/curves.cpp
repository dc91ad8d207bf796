// analysis_curves (curves.hpp): the report's traces as named columns with units.
#include "report/curves.hpp"

#include <array>
#include <utility>

namespace report {

using namespace detect;

namespace {

diag::DataGroup trace_group(std::string path, std::string description, const PlotTrace& t,
                            std::string x_name, std::string x_unit, std::string y_name,
                            std::string y_unit) {
  diag::DataGroup g;
  g.path = std::move(path);
  g.description = std::move(description);
  g.columns.push_back({std::move(x_name), std::move(x_unit), t.x});
  g.columns.push_back({std::move(y_name), std::move(y_unit), t.y});
  return g;
}

// One row per fault band or scored line of a bearing (Item: FaultBand, BearingLine): three
// leading columns (name, unit) and a last unit-free one read from each item by `row`, between
// them the item's family and harmonic; the items' labels joined by ';' (text "labels") and the
// legend of the family column (text "families").
template <class Item, class Row>
diag::DataGroup family_rows(std::string path, std::string description,
                            const std::vector<Item>& items,
                            const std::array<std::pair<const char*, const char*>, 3>& leading,
                            const char* last, Row row) {
  diag::DataGroup g;
  g.path = std::move(path);
  g.description = std::move(description);
  std::array<std::vector<double>, 6> values;
  std::string labels;
  for (const Item& item : items) {
    const std::array<double, 4> r = row(item);
    const std::array<double, 6> all = {
        r[0], r[1], r[2], static_cast<double>(item.family), static_cast<double>(item.harmonic),
        r[3]};
    for (std::size_t k = 0; k < all.size(); ++k) values[k].push_back(all[k]);
    labels += (labels.empty() ? "" : ";") + item.label;
  }
  for (std::size_t k = 0; k < leading.size(); ++k) {
    g.columns.push_back({leading[k].first, leading[k].second, std::move(values[k])});
  }
  g.columns.push_back({"family", "", std::move(values[3])});
  g.columns.push_back({"harmonic", "", std::move(values[4])});
  g.columns.push_back({last, "", std::move(values[5])});
  g.texts = {{"labels", labels}, {"families", "0 FTF;1 BPFO;2 BPFI;3 BALL (2 BSF)"}};
  return g;
}

void bearing_groups(const std::string& prefix, const ChannelAnalysis& c,
                    std::vector<diag::DataGroup>& out) {
  for (const BearingAnalysis& b : c.bearings) {
    diag::DataGroup g =
        family_rows(prefix + "/bearings/" + b.bearing + "/fault_bands",
                    "fault bands of bearing " + b.bearing +
                        " drawn on the envelope spectrum (families FTF, BPFO, BPFI, 2 BSF)",
                    b.bands, {{{"centre_hz", "Hz"}, {"low_hz", "Hz"}, {"high_hz", "Hz"}}},
                    "sideband", [](const FaultBand& fb) {
                      return std::array<double, 4>{fb.centre_hz, fb.low_hz, fb.high_hz,
                                                   static_cast<double>(fb.sideband)};
                    });
    const BearingFrequencies& f = b.frequencies;
    g.numbers = {{"shaft_hz", f.shaft_hz}, {"ftf_hz", f.ftf_hz},
                 {"bpfo_hz", f.bpfo_hz},   {"bpfi_hz", f.bpfi_hz},
                 {"bsf_hz", f.bsf_hz},     {"ball_fault_hz", f.ball_fault_hz}};
    if (b.diagnosed) {
      g.numbers["decision_band_low_hz"] = b.band_centre_hz - 0.5 * b.band_width_hz;
      g.numbers["decision_band_high_hz"] = b.band_centre_hz + 0.5 * b.band_width_hz;
    }
    out.push_back(std::move(g));
  }
}

// The channel's spectrogram: time_s, frequency_hz and psd_db[time][frequency] (2-D).
void spectrogram_group(const std::string& prefix, const ChannelAnalysis& c,
                       std::vector<diag::DataGroup>& out) {
  const SpectrogramTrace& s = c.spectrogram;
  if (s.time_s.size() < 2) return;
  diag::DataGroup g;
  g.path = prefix + "/spectrogram";
  g.description = "spectrogram: Welch PSD of each time span in dB (Hann, " +
                  std::to_string(2 * kSpectrogramRows) + "-sample segments, 50 % overlap)";
  g.columns = {{"time_s", "s", s.time_s},
               {"frequency_hz", "Hz", s.frequency_hz},
               {"psd_db",
                "dB re 1 " + (c.unit.empty() ? "unit^2" : squared_unit(c.unit)) + "/Hz",
                s.psd_db,
                {s.time_s.size(), s.frequency_hz.size()}}};
  g.texts["layout"] = "psd_db[time, frequency]";
  out.push_back(std::move(g));
}

// Per bearing diagnosed: the spectrum its decision read (band view) with the band's edges, and
// the lines it scored (seen: 1 where it counted them).
void decision_groups(const std::string& prefix, const ChannelAnalysis& c,
                     std::vector<diag::DataGroup>& out) {
  for (const BearingAnalysis& b : c.bearings) {
    if (b.decision_envelope.x.size() < 2) continue;
    const std::string p = prefix + "/bearings/" + b.bearing;
    out.push_back(trace_group(p + "/decision_envelope",
                              "squared envelope spectrum of the prewhitened signal in the band "
                              "the bearing decision used (its band view)",
                              b.decision_envelope, "frequency_hz", "Hz", "amplitude", ""));
    out.back().numbers = {{"band_low_hz", b.band_centre_hz - 0.5 * b.band_width_hz},
                          {"band_high_hz", b.band_centre_hz + 0.5 * b.band_width_hz}};
    out.back().texts["status"] = b.diagnosis.status == BearingDecisionStatus::kFault
                                     ? finding_name(b.diagnosis.fault)
                                     : to_string(b.diagnosis.status);
    out.push_back(family_rows(
        p + "/decision_lines", "every harmonic the bearing decision scored on that spectrum",
        b.lines, {{{"expected_hz", "Hz"}, {"found_hz", "Hz"}, {"prominence_db", "dB"}}}, "seen",
        [](const BearingLine& l) {
          return std::array<double, 4>{l.expected_hz, l.found_hz, l.prominence_db,
                                       l.seen ? 1.0 : 0.0};
        }));
  }
}

}  // namespace

std::string squared_unit(const std::string& unit) {
  if (unit.empty()) return "";
  const bool compound = unit.find_first_of("/^* ") != std::string::npos;
  return (compound ? "(" + unit + ")" : unit) + "^2";
}

std::vector<diag::DataGroup> analysis_curves(const AnalysisResult& r) {
  std::vector<diag::DataGroup> out;
  if (r.speed.time_s.size() > 1) {
    diag::DataGroup g;
    g.path = "speed";
    g.description = "speed of shaft " + r.speed.reference_shaft + " from the " + r.speed.source;
    g.columns = {{"time_s", "s", r.speed.time_s}, {"speed_rpm", "rpm", r.speed.speed_rpm}};
    g.texts = {{"source", r.speed.source}, {"shaft", r.speed.reference_shaft}};
    out.push_back(std::move(g));
  }
  const std::string domain = r.speed.spectra_domain == "order" ? "order" : "time";
  for (const ChannelAnalysis& c : r.channels) {
    if (!c.vibration) continue;
    const std::string p = "channels/" + c.name;
    const std::size_t first = out.size();
    if (c.waveform.x.size() > 1) {
      out.push_back(trace_group(p + "/waveform", "time waveform (min/max decimated)", c.waveform,
                                "time_s", "s", "value", c.unit));
    }
    if (!c.kurtogram.empty()) {
      diag::DataGroup g;
      g.path = p + "/kurtogram";
      g.description = "fast kurtogram: one row per band of every level";
      std::vector<double> level, low, high, kurt;
      for (const KurtogramLevel& l : c.kurtogram) {
        for (std::size_t i = 0; i < l.kurtosis.size(); ++i) {
          level.push_back(l.level);
          low.push_back(static_cast<double>(i) * l.bandwidth_hz);
          high.push_back(static_cast<double>(i + 1) * l.bandwidth_hz);
          kurt.push_back(l.kurtosis[i]);
        }
      }
      g.columns = {{"level", "", std::move(level)},
                   {"band_low_hz", "Hz", std::move(low)},
                   {"band_high_hz", "Hz", std::move(high)},
                   {"kurtosis", "", std::move(kurt)}};
      g.numbers = {{"selected_level", c.kurtogram_level},
                   {"selected_kurtosis", c.kurtogram_kurtosis},
                   {"selected_low_hz", c.envelope_low_hz},
                   {"selected_high_hz", c.envelope_high_hz}};
      out.push_back(std::move(g));
    }
    if (c.spectrum.x.size() > 1) {
      out.push_back(trace_group(p + "/spectrum", "amplitude spectrum (Hann, peak scaling)",
                                c.spectrum, "frequency_hz", "Hz", "amplitude", c.unit));
    }
    if (c.psd.x.size() > 1) {
      out.push_back(trace_group(p + "/psd", "Welch power spectral density", c.psd, "frequency_hz",
                                "Hz", "psd", squared_unit(c.unit) + (c.unit.empty() ? "" : "/Hz")));
      out.back().numbers = {{"resolution_hz", c.psd_resolution_hz},
                            {"segments", static_cast<double>(c.psd_segments)}};
    }
    if (c.envelope.x.size() > 1) {
      out.push_back(trace_group(p + "/envelope_spectrum",
                                "envelope spectrum demodulated in the kurtogram's band", c.envelope,
                                "frequency_hz", "Hz", "amplitude", c.unit));
      out.back().numbers = {{"band_low_hz", c.envelope_low_hz},
                            {"band_high_hz", c.envelope_high_hz}};
      bearing_groups(p, c, out);
    }
    decision_groups(p, c, out);
    spectrogram_group(p, c, out);
    for (const MeshAnalysis& m : c.meshes) {
      if (m.zoom.x.size() < 2) continue;
      out.push_back(trace_group(p + "/meshes/" + m.name + "/zoom",
                                "amplitude spectrum around the mesh frequency", m.zoom,
                                "frequency_hz", "Hz", "amplitude", c.unit));
      out.back().numbers = {{"mesh_hz", m.mesh_hz}};
    }
    if (c.order_spectrum.x.size() > 1) {
      out.push_back(trace_group(p + "/order_spectrum",
                                "order spectrum in orders of the input shaft " + r.input_shaft,
                                c.order_spectrum, "order", "cycles/rev", "amplitude", c.unit));
    }
    for (const ShaftTsaAnalysis& t : c.tsa) {
      if (!t.computed || t.tsa.empty()) continue;
      diag::DataGroup g;
      g.path = p + "/tsa/" + t.shaft;
      g.description = "time-synchronous average of shaft " + t.shaft +
                      " over one revolution, with its regular, residual and difference signals";
      std::vector<double> angle(t.tsa.size());
      for (std::size_t i = 0; i < angle.size(); ++i) {
        angle[i] = static_cast<double>(i) / static_cast<double>(angle.size());
      }
      g.columns = {{"angle_rev", "rev", std::move(angle)},
                   {"tsa", c.unit, t.tsa},
                   {"regular", c.unit, t.regular},
                   {"residual", c.unit, t.residual},
                   {"difference", c.unit, t.difference}};
      g.numbers = {{"revolutions", static_cast<double>(t.revolutions)}};
      out.push_back(std::move(g));
    }
    for (std::size_t i = first; i < out.size(); ++i) {
      out[i].texts["channel"] = c.name;
      // The time-domain groups (waveform, kurtogram) and the TSA are not spectra.
      const std::string& q = out[i].path;
      if (!q.ends_with("/fault_bands") && !q.ends_with("/waveform") && !q.ends_with("/kurtogram") &&
          !q.ends_with("/spectrogram") && q.find("/tsa/") == std::string::npos) {
        out[i].texts["domain"] = domain;
      }
    }
  }
  return out;
}

}  // namespace report
