// analyze's text summary writer (format_summary, report.hpp).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "diag/util/number_format.hpp"
#include "report/report.hpp"

namespace report {

using namespace detect;

std::string format_summary(const AnalysisResult& r) {
  const auto labels = [&](const std::vector<std::string>& names) {
    std::vector<std::string> out;
    for (const std::string& n : names) out.push_back(channel_label(r, n));
    return diag::format_list(out);
  };
  std::ostringstream o;
  o << "recording: " << r.channels.size() << " channels, "
    << diag::format_significant(r.duration_s, 6) << " s";
  if (!r.gearbox_name.empty()) o << ", gearbox " << r.gearbox_name;
  o << "\n";
  if (r.coverage) {
    const AnalysisCoverage& c = *r.coverage;
    o << "examined: " << diag::format_significant(c.analysed_s, 6) << " s of "
      << diag::format_significant(c.duration_s, 6) << " s";
    if (c.frames > 1) {
      o << ", in " << c.frames_examined << " of " << c.frames << " frames of "
        << diag::format_significant(c.frame_s, 4) << " s";
    }
    o << (c.complete() ? " (every sample)" : ": NOT EVERY SAMPLE EXAMINED") << "\n";
    for (const std::string& n : c.not_examined) o << "  not examined: " << n << "\n";
  }
  if (!r.speed.source.empty()) {
    o << "  speed of " << r.speed.reference_shaft << " from the " << r.speed.source
      << (r.speed.line.empty() ? "" : " (" + r.speed.line + ")") << ": "
      << diag::format_significant(r.speed.mean_rpm, 6) << " rpm";
    if (!r.speed.stationary) {
      o << ", varying " << diag::format_significant(r.speed.min_rpm, 5) << " .. "
        << diag::format_significant(r.speed.max_rpm, 5) << " rpm";
    }
    o << " (nominal " << diag::format_significant(r.speed.nominal_rpm, 6) << " rpm)\n";
  }
  for (const auto& s : r.shafts) {
    o << "  shaft " << s.shaft << ": " << diag::format_significant(s.speed_hz * 60, 6) << " rpm ("
      << s.source << ")\n";
  }
  for (const auto& m : r.meshes) {
    o << "  mesh " << m.name << ": " << diag::format_significant(m.frequency_hz, 6) << " Hz\n";
  }
  o << "channels:\n";
  for (const auto& c : r.channels) {
    o << "  " << channel_label(c) << " [" << (c.unit.empty() ? "-" : c.unit) << "] rms "
      << diag::format_significant(c.time.rms, 3) << " peak "
      << diag::format_significant(c.time.peak, 3) << " crest "
      << diag::format_significant(c.time.crest_factor, 3) << " kurtosis "
      << diag::format_significant(c.time.kurtosis, 3);
    if (c.vibration && !c.spectrum_peaks.empty()) {
      o << "; top line " << diag::format_significant(c.spectrum_peaks.front().frequency_hz, 6)
        << " Hz";
    }
    o << "\n";
  }
  if (!r.two_direction.empty()) {
    o << "two directions (normal / along at the mesh harmonics):\n";
    for (const auto& t : r.two_direction) {
      o << "  " << t.location << " mesh " << t.mesh << ": "
        << diag::format_significant(t.comparison.normal_to_along_db, 3) << " dB ("
        << channel_label(r, t.along_channel) << " / " << channel_label(r, t.normal_channel)
        << ")\n";
    }
  }
  if (r.gear_damage) {
    o << "damaged-shaft location (TSA per shaft, angles from the " << r.gear_damage_angles
      << "): " << r.gear_damage->status << "\n";
    for (const auto& s : r.gear_damage->shafts) {
      o << "  " << s.shaft << ": ";
      if (s.revolutions == 0) {
        o << "skipped\n";
        continue;
      }
      o << "score " << diag::format_significant(s.score, 3) << ", SNR "
        << diag::format_significant(s.snr, 3) << ", level " << diag::format_significant(s.level, 3)
        << " on " << channel_label(r, s.channel) << " (" << s.revolutions << " revolutions)"
        << (s.damaged     ? ": DAMAGED"
            : s.uncertain ? ": uncertain"
                          : "")
        << "\n";
    }
  }
  o << "findings:";
  if (r.findings.empty()) {
    o << (r.coverage && !r.coverage->complete() ? " none in the part examined (not every sample)"
                                                : " none");
  }
  o << "\n";
  const bool framed = r.coverage && r.coverage->frames > 1;
  for (const auto& f : r.findings) {
    const std::string where = !f.bearing.empty()
                                  ? f.bearing + " " + std::string(diag::to_string(f.fault))
                              : !f.shaft.empty() ? f.shaft
                                                 : std::string(diag::to_string(f.fault));
    o << "  [" << diag::format_significant(f.confidence, 2) << "] "
      << (f.kind == "baseline" ? "baseline ALARM" : f.kind) << ": " << where
      << (f.channel.empty() ? "" : ", best seen on " + channel_label(r, f.channel));
    if (framed && std::isfinite(f.first_s)) {
      o << ", " << diag::format_significant(f.first_s, 5) << "-"
        << diag::format_significant(f.last_s, 5) << " s";
    }
    o << " - " << f.note << "\n";
  }
  if (r.baseline) {
    o << "anomaly score " << diag::format_significant(r.baseline->anomaly_score, 3)
      << " (threshold " << diag::format_significant(r.baseline->threshold, 3)
      << "): " << (r.baseline->alarm ? "ALARM" : "normal") << "\n";
    const auto& ch = r.baseline->channels;
    o << "  against " << r.baseline->recordings.size() << " baseline recordings ("
      << r.baseline->samples << " samples), "
      << (ch.size() <= 6 ? "channels " + labels(ch) : std::to_string(ch.size()) + " channels")
      << "\n";
    for (std::size_t k = 0; k < std::min<std::size_t>(3, r.baseline->deviations.size()); ++k) {
      const auto& d = r.baseline->deviations[k];
      o << "  " << d.feature << ": z " << diag::format_significant(d.z, 3) << " ("
        << diag::format_significant(d.value, 3) << " against "
        << diag::format_significant(d.baseline_centre, 3) << " +- "
        << diag::format_significant(d.baseline_spread, 3) << ")\n";
    }
    for (const auto& w : r.baseline->wear)
      o << "  wear, mesh " << w.mesh << " (" << diag::format_significant(w.mesh_hz, 3)
        << " Hz): harmonics " << diag::format_significant(w.growth_db, 3)
        << " dB against the baseline (threshold " << diag::format_significant(w.threshold_db, 3)
        << " dB)" << (w.flagged ? ": WORN" : "") << "\n";
    for (const auto& n : r.baseline->notes) o << "  note: " << n << "\n";
  }
  for (const auto& n : r.notes) o << "note: " << n << "\n";
  return o.str();
}

}  // namespace report
