// `geardiag batch` as a call (tools/cmd_batch.cpp): the analysis of many recordings into one row
// each, and a machine's history (the recordings in time order, the first ones its healthy
// reference, every later one judged against it; docs/cli/batch.md). `geardiag validate
// --history` runs every life history of a dataset through it, as a user's batch would.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "channel_options.hpp"
#include "parallel.hpp"

namespace geardiag {

struct BatchRequest {
  std::vector<std::string> files;      // the recordings, in the order given
  std::vector<std::string> baselines;  // --baseline (not in a history)
  int healthy_first = 0;               // a history: the first K in time order are the reference
  std::vector<std::string> healthy;    // a history: these recordings are the reference
  std::string gearbox;                 // --gearbox (empty: each file's own description)
  ChannelOptions channels;
  std::optional<double> fs;
  std::string reports;       // --reports: the folder of every recording's own HTML report
  std::string load_channel;  // --load: a channel whose RMS is the machine's load
  int jobs = 1;              // worker threads of this process (resolved)
  bool progress = true;      // a progress line on a terminal
};

struct BatchResult {
  bool history = false;
  std::vector<std::string> files;  // in the table's order (a history's: the reference first)
  std::vector<bool> reference;     // a history: which rows are the reference
  std::string order = "given";     // "time" when the history was put in time order
  std::vector<std::string> notes;
  // Rank 0 only: one row per file (file, time, status, error, speed_rpm, anomaly_score, alarm,
  // alarm_threshold, findings (short), finding_list (analyze --json's), features, ...; a
  // history's also index and reference), and the history's events.
  std::vector<nlohmann::json> rows;
  nlohmann::json events = nlohmann::json::array();
  // A history's damaged-shaft locator gates ("<shaft>/score", "<shaft>/score_alone"): a later
  // recording's gear damage on the shaft stands above one of them (cmd_batch.cpp).
  std::map<std::string, double> locator_gate;
  // Its bearing lines' growth gates ("bearing/<bearing>/<BPFO|BPFI|BSF>_db"): the reference's
  // largest of the line plus the growth margin; a later recording's line above one is a finding.
  std::map<std::string, double> bearing_gate;
  // Its wear thresholds per mesh [dB], from the reference's own spread: a later recording's
  // growth above one is a wear finding (cmd_batch.cpp, wear_gates).
  std::map<std::string, double> wear_gate;
  // A history's operating states, as learned from its reference: per state "speed_rpm" [lo, hi]
  // (absent without speeds), "load" [lo, hi] (with a load channel), "reference" (its rows) and
  // "wear" per mesh {"reference_recordings", "mean_db", "sd_db", "threshold_db"}.
  nlohmann::json states = nlohmann::json::array();
};

// Checks the request (diag::InputError naming the option), orders a history, reads the baseline,
// analyses every file (split across the ranks of `world`, run on request.jobs threads) and, on
// rank 0, gathers the rows and judges the history.
BatchResult run_batch(BatchRequest request, const MpiWorld& world);

}  // namespace geardiag
