// The two-direction comparison (docs/physics.md, "two directions"; seed 000, Kalinin &
// Temis 2018): bearing vibration measured along a mesh's line of action (LOA) reflects the
// transmission error (tooth geometry, defects, stiffness); normal to the LOA it is driven by
// mesh friction alone (surface state, lubrication, temperature, early pitting). Comparing the
// two at the mesh harmonics gives a friction/surface-condition indicator.
//
// For each mesh harmonic h = 1..H the energy of each direction's amplitude spectrum is summed
// over the band h f_mesh +- halfwidth and converted to the tone's mean square:
//   E_h = sum_{k in band} A_k^2 / (2 ENBW_bins),
// A_k a peak-scaled amplitude spectrum (spectrum.hpp), ENBW_bins the window's equivalent noise
// bandwidth in bins. Why: a windowed tone of amplitude a spreads over the bins as
// a^2 |W(k - k0)|^2 / W(0)^2, and sum_k |W(k)|^2 / W(0)^2 = ENBW_bins (Parseval; Heinzel,
// Ruediger & Schilling 2002, "Spectrum and spectral density estimation by the DFT", eq. 22), so
// E_h = a^2 / 2, the tone's mean square, wherever it falls between bins, as long as the band
// holds its main lobe.
// The indicator is the normal-to-along ratio at the mesh harmonics, in dB:
//   R = 10 log10( sum_h E_h(normal) / sum_h E_h(along) ),
// larger when friction (normal) grows relative to the transmission-error (along) excitation:
// lower oil temperature, higher mu, a rougher surface (Fig. 11 of seed 000).
#pragma once

#include <string>
#include <vector>

#include "detect/gear/fault_bands.hpp"

namespace detect {

struct TwoDirectionOptions {
  int mesh_harmonics = 3;     // H: harmonics 1..H summed, 1..50
  double halfwidth_hz = 0.0;  // band half-width around each harmonic [Hz], >= 0;
                              // 0: max(4 bins, 1 % of the harmonic's frequency) (speed jitter,
                              // the window's main lobe: 2.5 bins for Hann, 5 for flat-top)
  void validate() const;      // throws diag::InputError naming the field
};

struct HarmonicEnergy {
  int harmonic = 1;         // h
  double frequency_hz = 0;  // h f_mesh
  double along = 0;         // E_h along the LOA [unit^2] (mean square of the tone)
  double normal = 0;        // E_h normal to the LOA [unit^2]
  bool valid = false;       // false when the band leaves either spectrum (not summed)
};

struct TwoDirectionComparison {
  double mesh_hz = 0;
  std::vector<HarmonicEnergy> harmonics;  // h = 1..H
  double along_energy = 0;                // sum of the valid harmonics' E_h along [unit^2]
  double normal_energy = 0;               // same, normal [unit^2]
  // 10 log10(normal_energy / along_energy) [dB], clipped to +-kMaxProminenceDb (a zero side in
  // a noise-free synthetic signal); NaN when both are zero or no harmonic is valid.
  double normal_to_along_db = 0;
};

// `along` and `normal`: peak-scaled amplitude spectra of the two channels (uniform bins,
// validated here), computed with the same window, whose equivalent noise bandwidth in bins is
// enbw_bins in units of this spectrum's bin spacing (> 0; Spectrum::enbw_hz / resolution_hz,
// which holds with zero padding too).
// Throws diag::InputError for malformed spectra, mesh_hz <= 0 or bad options.
TwoDirectionComparison compare_two_directions(const SpectrumView& along, const SpectrumView& normal,
                                              double enbw_bins, double mesh_hz,
                                              const TwoDirectionOptions& opt = {});

// Mean-square energy of the band [low_hz, high_hz] of a peak-scaled amplitude spectrum: the
// E_h formula above for any band (bins whose frequency lies inside, edges included).
double band_mean_square(const SpectrumView& spectrum, double enbw_bins, double low_hz,
                        double high_hz);

}  // namespace detect
