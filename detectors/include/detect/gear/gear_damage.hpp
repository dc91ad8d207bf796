// Which shaft carries a damaged gear: time-synchronous averages per shaft from one tachometer
// (McFadden 1987; Stewart 1977's difference signal and FM4, Zakrajsek et al. 1993).
//
// Method.
//  1. Pulse times of one shaft's tacho (the input's when present, else the first tacho of a
//     known shaft), repaired (tacho.hpp); every other shaft's revolutions by scale_pulses() with
//     the gearbox speed ratio f_s / f_ref.
//  2. For each shaft s that carries gears, the TSA of each of its channels (below) over s's
//     revolutions, and its difference signal d_s (tsa.hpp): TSA minus shaft order 1, minus every
//     mesh frequency of the gearbox that is an integer order of s (all its harmonics below the
//     Nyquist order) and their first-order sidebands. A mesh of another shaft pair that is
//     synchronous with s (in the two-stage box the second mesh is order 9 of the input shaft) is a
//     tone in s's TSA and must go as well, else it dominates d_s.
//  3. The exclusive difference signal e_s: d_s without the orders that s shares with any faster
//     shaft f, i.e. without the multiples of p where f_f / f_s = p / q in lowest terms (q <= 64).
//     Why: with integer ratios a localised fault on a fast shaft is also periodic with every
//     slower shaft, so it appears in the slower shafts' TSAs as k = f_f / f_s equal impulses per
//     revolution (only at orders k, 2k, ...), and a fault on a slow shaft appears folded into the
//     faster shafts' TSAs (1/k of its amplitude, once per fast revolution). Removing the shared
//     orders makes e_s blind to faults on faster shafts; a fault on s keeps (k - 1)/k of its
//     energy in e_s (a single impulse minus its k-fold folded copy: still impulsive).
//  4. Score_s = FM4(e_s) = N sum e^4 / (sum e^2)^2, the kurtosis of e_s (about 3 when e_s is
//     Gaussian noise; its standard deviation is about sqrt(24 / M), M = 2 x the orders kept),
//     the largest over the shaft's channels. e_s keeps orders up to max_order_fraction of the
//     Nyquist order and loses extra_sideband_orders more sidebands around its own mesh orders.
//  5. Decision. A shaft is flagged when its score exceeds damaged_fm4 and "uncertain" above
//     healthy_fm4. The damaged shaft is the SLOWEST flagged shaft: a fault on s can flag faster
//     shafts (the folded copy) but never slower ones (step 3). No flagged shaft: "healthy". When
//     a shaft slower than the chosen one lies in the uncertain band, the answer is "ambiguous"
//     and both shafts are reported.
//
// Channels per shaft: options.channels[shaft] when given; else the recording's signals whose
// location is a bearing of that shaft ("<shaft>_bearing1", the simulator's names, or a bearing of
// the gearbox description on that shaft) and direction along a line of action (one channel per
// mesh of the shaft); else every such bearing signal of the shaft; else every signal whose
// direction is along/normal to a line of action, horizontal or vertical (a single sensor on the
// casing serves all shafts).
//
// CAUTION: kurtosis answers "is there a localised event once per revolution", not "how large";
// a fault spread over all teeth (uniform wear) does not raise it. Shafts with fewer than
// min_revolutions whole revolutions in the record are skipped and named in the result's note.
#pragma once

#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "detect/indicators/indicators.hpp"
#include "diag/gearbox/gearbox.hpp"
#include "diag/io/recording.hpp"

namespace detect {

struct GearDamageOptions {
  int samples_per_rev = 512;  // TSA angular resolution [samples/rev], power of two >= 64; keep
                              // >= 2.8 x 3 x the largest tooth count so that three mesh
                              // harmonics pass the resampling filter unattenuated
  int min_revolutions = 8;    // fewer whole revolutions of a shaft than this: the shaft is
                              // skipped (noted), >= 2
  // Degree of the least-squares polynomial t(k) fitted to the reference tacho's pulse times
  // (k the pulse index), which replaces them; 0: the pulse times as detected. [0, 8]. Why: a
  // 0/1 pulse train's edges are known only to +- half a sampling period (tacho.hpp), which at the
  // high mesh harmonics (kHz) is a phase jitter of tens of degrees per revolution; the TSA turns
  // it into spurious impulsive content that FM4 reads as damage. A degree-3 fit is exact for
  // constant speed and for a linear run-up over a short record, and averages the jitter over
  // all pulses. Use 0 when the speed wanders within the record.
  int pulse_fit_degree = 3;
  // Sidebands beyond the first also removed around every harmonic of the shaft's OWN gears' mesh
  // orders (other meshes synchronous with the shaft lose their first sidebands only: the second
  // mesh is order 9 of the input shaft, and +-3 sidebands around it would leave 2 orders in 9),
  // >= 0. Why 2: the simulated healthy gearbox modulates its large mesh
  // harmonics near the casing/shaft resonances at a few shaft orders (the drive's torsional
  // mode); those sidebands are not synchronous, leak into the TSA at about 1/N and, clustered at
  // every mesh harmonic, are impulsive (healthy input-shaft FM4 10-13 with 0, < 3 with 2).
  int extra_sideband_orders = 0;
  // Keep orders up to this fraction of the Nyquist order samples_per_rev / 2 in the exclusive
  // signal, (0, 1]. Why 0.25 (orders <= 64 at 512 samples/rev, about 3.5 mesh harmonics of the
  // largest gear): in the simulated healthy gearbox the mesh harmonics near the structural
  // resonances (kHz) are tens of times larger than the fault's sidebands and carry
  // non-synchronous modulation that leaks into the TSA at ~1/N; cutting them brought the healthy
  // input-shaft FM4 from 9.5 to 4.6 at 2000 rpm while a missing z1 tooth rose from 18 to 23.
  double max_order_fraction = 0.25;
  // A slower shaft's exclusive signal must hold at least this share of the energy of its
  // difference signal to be flagged, [0, 1). A fault on the shaft leaves (k - 1)/k >= 1/2 of its
  // impulse's energy there (k the ratio to the next faster shaft), noise about the share of
  // orders kept; a large fault on a FASTER shaft leaks into it only through the non-synchronous
  // part of its response, a few per cent. Shafts with no faster shaft are not tested.
  double min_exclusive_share = 0.2;
  // Thresholds on FM4 of the exclusive difference signal. Gaussian noise gives 3 with a standard
  // deviation about sqrt(24/M), M = 2 x the orders kept (the even orders of the counter and
  // output shafts are shared with faster shafts: about 27 odd orders kept, 0.67); healthy
  // simulated gearboxes gave 2.7-3.6 on the counter and output shafts and 4.4-4.9 on the input
  // shaft (1000-2500 rpm: its mesh harmonics are the largest). damaged_fm4 = 6 leaves > 1 above
  // the worst healthy value seen; validation/gear_damage_loop measures the false-alarm rate.
  double damaged_fm4 = 6.0;     // score above this: damaged, > healthy_fm4
  double healthy_fm4 = 4.5;     // score above this (and below damaged_fm4): uncertain, > 3
  std::string reference_shaft;  // shaft whose tacho gives the pulses; empty: the input shaft's
                                // tacho, else the first tacho whose location is a known shaft
  std::map<std::string, std::vector<std::string>> channels;  // shaft -> channels to use
                                                             // (overrides the automatic choice)

  void validate() const;  // throws diag::InputError naming the field
};

struct ShaftDamage {
  std::string shaft;
  double frequency_hz = 0;     // mean rotation frequency over the record [Hz]
  int revolutions = 0;         // whole revolutions averaged (0: skipped)
  GearIndicators indicators;   // of the TSA and difference signal of `channel`, for the
                               // shaft's first gear as the monitored mesh (reporting only)
  std::string channel;         // the channel that gave the score
  double score = 0;            // FM4 of the exclusive difference signal (NaN when skipped)
  double exclusive_share = 1;  // energy of the exclusive over the difference signal
  bool damaged = false;        // score > damaged_fm4 and exclusive_share >= min_exclusive_share
  bool uncertain = false;      // healthy_fm4 < score <= damaged_fm4
};

struct GearDamageFinding {
  std::string shaft;
  std::vector<std::string> gears;  // every gear on the shaft (they share its revolution)
  std::string channel;
  double score = 0;       // the shaft's score (FM4)
  double confidence = 0;  // [0, 1]: min(1, (score - healthy_fm4) / (2 (damaged_fm4 -
                          // healthy_fm4))), halved when ambiguous
  std::string note;
};

struct GearDamageResult {
  std::vector<ShaftDamage> shafts;  // in gearbox order
  std::vector<GearDamageFinding> findings;
  // "healthy": no shaft flagged; "damaged": one shaft; "ambiguous": two candidate shafts, both
  // reported (a slower shaft in the uncertain band below the flagged one).
  std::string status = "healthy";
  std::string reference_shaft;  // shaft whose tacho was used
  std::string note;             // skipped shafts, tacho repairs
};

// Throws diag::InputError for bad options, a recording without a usable tacho, a shaft named in
// options.channels that does not exist, or a missing channel.
GearDamageResult locate_gear_damage(const diag::Recording& rec, const diag::Gearbox& gb,
                                    const GearDamageOptions& options = {});

// {"status", "reference_shaft", "note", "shafts": [...], "findings": [{"shaft", "gears",
// "channel", "score", "confidence", "note"}]}: the findings share "shaft", "gears",
// "confidence" and "note" with `geardiag attribute`'s.
nlohmann::json to_json(const GearDamageResult& r);

}  // namespace detect
