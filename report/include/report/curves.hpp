// Every curve of an analysis (detect/analysis/analyze.hpp), as named columns with their units
// (diag/io/ data_groups.hpp): what `geardiag analyze --curves OUT.h5` writes and what the Python
// module's analyze() returns as numpy arrays. The curves are the report's own (AnalysisResult's
// traces, peak-hold decimated to AnalyzeOptions::plot_points; the TSA signals at full angular
// resolution), so a curve read from the file is the one drawn in the HTML report.
//
// Groups (<ch>: channel name, <sh>: shaft, <b>: bearing, <m>: mesh):
//   speed                              time_s [s], speed_rpm [rpm] (the reference shaft's speed;
//                                      absent when the nominal speed was used)
//   channels/<ch>/waveform             time_s [s], value [unit] (min/max decimated)
//   channels/<ch>/kurtogram            level, band_low_hz, band_high_hz [Hz], kurtosis: one row
//                                      per band of every level; numbers selected_level,
//                                      selected_kurtosis, selected_low_hz, selected_high_hz
//   channels/<ch>/spectrum             frequency_hz [Hz], amplitude [unit] (peak scaling, Hann)
//   channels/<ch>/psd                  frequency_hz [Hz], psd [(unit)^2/Hz] (Welch)
//   channels/<ch>/envelope_spectrum    frequency_hz [Hz], amplitude [unit]; numbers band_low_hz,
//                                      band_high_hz (the kurtogram's demodulation band)
//   channels/<ch>/bearings/<b>/fault_bands
//                                      centre_hz, low_hz, high_hz [Hz], family, harmonic, sideband;
//                                      texts labels (";"-separated) and families; numbers ftf_hz,
//                                      bpfo_hz, bpfi_hz, bsf_hz, ball_fault_hz, shaft_hz and the
//                                      decision's band (decision_band_low_hz, ..._high_hz)
//   channels/<ch>/bearings/<b>/decision_envelope
//                                      frequency_hz [Hz], amplitude (unit-free): the squared
//                                      envelope spectrum of the prewhitened signal the bearing
//                                      decision read; numbers band_low_hz, band_high_hz (its
//                                      band); text status (the fault named, or no_fault/ambiguous)
//   channels/<ch>/bearings/<b>/decision_lines
//                                      expected_hz, found_hz [Hz], prominence_db [dB], family,
//                                      harmonic, seen (1: counted by the decision); text labels
//   channels/<ch>/spectrogram          time_s [s], frequency_hz [Hz], psd_db [dB re 1 unit^2/Hz]
//                                      2-D [time, frequency] (analyze.hpp, SpectrogramTrace)
//   channels/<ch>/meshes/<m>/zoom      frequency_hz [Hz], amplitude [unit] around the mesh line
//   channels/<ch>/order_spectrum       order [cycles/rev of the input shaft], amplitude [unit]
//   channels/<ch>/tsa/<sh>             angle_rev [rev], tsa, regular, residual, difference [unit]
// At varying speed the channel spectra are order spectra read at the mean speed (analyze.hpp);
// the group text `domain` says "order" then, else "time".
#pragma once

#include <string>
#include <vector>

#include "detect/analysis/analyze.hpp"
#include "diag/io/data_groups.hpp"

namespace report {

// The curves listed above, in a fixed order (speed, then channels as analysed).
std::vector<diag::DataGroup> analysis_curves(const detect::AnalysisResult& r);

// The unit of a power or PSD of a quantity in `unit`: "m/s^2" -> "(m/s^2)^2", "g" -> "g^2";
// "" -> "".
std::string squared_unit(const std::string& unit);

}  // namespace report
