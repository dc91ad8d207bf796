// Defect attribution from the output shaft's kinematic irregularity by recurrence-period matching
// (seed 003, Antipenko & Shambalova 2012, Fig. 10; docs/physics.md).
//
// Input: the input and output shaft angles sampled together (any step, uniform or not, input
// angle non-decreasing) and the gearbox description. Steps:
//  1. delta_phi = phi_in / u - phi_out (the output's lag behind its theoretical angle).
//  2. The smooth periodic part (runout of every shaft on the power path, mesh-harmonic TE) is
//     removed by backfitting: for each path shaft in turn, the synchronous average of the partial
//     residual over that shaft's angle, kept to its low orders (1..smooth_harmonics) and the mesh
//     orders of its gears (k z, k = 1..mesh_harmonics). Samples inside detected events are left
//     out of the averages and the fit is repeated, so the defects do not leak into it.
//  3. Events: runs of the residual above threshold_sigma robust noise sigmas (1.4826 MAD), with
//     hysteresis at half the threshold; each event has a height (its size at the output) and an
//     onset (input angle at which the lag starts to grow).
//  4. Trains: for each distinct recurrence period T of the path shafts, shortest first, events
//     are grouped by their phase modulo T; a group whose expected positions are hit in at least
//     min_coverage of the recurrences the record holds becomes a train; its period is measured by
//     a least-squares fit of onset vs recurrence index and must match T within period_tolerance.
//     A train whose every m-th recurrence is higher (beyond the noise) than the others, where m
//     times its period is a slower path shaft's period, is read as this train plus a defect on
//     the slower shaft passing at the same time (the seed's Fig. 9); the alternative reading (m
//     defects on the slower shaft) is named in the finding's note and the confidence is halved.
//  5. Coincidences: an event during which another train also passes is the overlap of two
//     defects; its height and onset belong to neither alone (in the seed's model the output
//     stays stopped while either gap is taken up, so they neither add nor keep their own shape).
//     Each train is sized and its period fitted from the events that do not coincide with
//     another train's (when at least two remain), and an event no train claimed but during which
//     trains pass (a pulse split by the overlap) is explained by those trains, not left over.
//  6. Findings: each train is attributed to the shaft with that period and lists every gear on the
//     shaft that meshes on the power path; size at the output is the median height of its sizing
//     events, at the gear it is that times u_i (seed eq. 4). Events no train explains are
//     reported as `unexplained` with multiplicity = true instead of a guess.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>
#include <vector>

#include "detect/finding.hpp"
#include "diag/gearbox/gearbox.hpp"

namespace detect {

struct AttributionOptions {
  double threshold_sigma = 8.0;       // event threshold [robust noise sigmas], >= 3
  double min_event_rad = 1e-5;        // absolute floor of the event threshold at the output
                                      // [rad], >= 0 (quantisation and numerical noise)
  double position_tolerance_rad = 0;  // an event within this input angle of a train's expected
                                      // position belongs to it [rad]; 0: automatic,
                                      // max(5 steps, 0.5 deg)
  double period_tolerance = 0.01;     // relative match of a measured period to T_i, (0, 0.2]
  double min_coverage = 0.75;         // fraction of recurrences a train must show, (0, 1]
  int smooth_harmonics = 6;           // shaft orders removed per path shaft, 0..64
  int mesh_harmonics = 3;             // mesh orders removed per path gear, 0..8
  int min_recurrences = 5;            // record must hold this many of the longest period, >= 2

  void validate() const;  // throws diag::InputError naming the field
};

// The findings (finding.hpp) are kind "attribution", fault tooth_damage, one per train: shaft
// (several joined by " or " when they share the period), gears (every path gear on it), size the
// size in the gear's own rotation [rad] (size_output_rad x u_i), confidence = coverage x period
// match x height consistency, note (another reading of the same events, when one fits), and the
// evidence:
//   period_input_rev           the matched recurrence period T_i [input revolutions]
//   measured_period_input_rev  least-squares period of the train
//   size_output_rad            median event height at the output [rad]
//   size_gear_rad              = size
//   first_event_input_rad      onset of the train's first recurrence [rad of input]
//   events, expected_events    recurrences seen / that the record holds
//   coincident_events          events where another train passes too (not used for the size)
struct UnexplainedEvent {
  double input_angle_rad = 0;  // onset
  double size_output_rad = 0;  // height
};

enum class AttributionStatus {
  kHealthy,       // no event above the threshold
  kAttributed,    // every event belongs to a train that matched a recurrence period
  kMultiplicity,  // some events are explained by no period: several defects, not separable
};

struct AttributionResult {
  AttributionStatus status = AttributionStatus::kHealthy;
  std::vector<Finding> findings;
  bool multiplicity = false;
  std::vector<UnexplainedEvent> unexplained;
  int events_detected = 0;
  double noise_rad = 0;      // robust sigma of the residual
  double threshold_rad = 0;  // event threshold used
  double record_input_rev = 0;
};

// Throws diag::InputError for mismatched lengths, non-finite samples, a decreasing input angle,
// an angle ratio that contradicts the gearbox, or a record shorter than min_recurrences of the
// longest period (the message says how many input revolutions are needed).
AttributionResult attribute_defects(std::span<const double> input_angle_rad,
                                    std::span<const double> output_angle_rad,
                                    const diag::Gearbox& gb, const AttributionOptions& options);

// {"findings": [...], "multiplicity": bool, "unexplained": [...], ...} with the keys of
// docs/cli/attribute.md.
nlohmann::json to_json(const AttributionResult& r);
std::string format_table(const AttributionResult& r);
std::string_view to_string(AttributionStatus s);

}  // namespace detect
