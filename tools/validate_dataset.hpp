// geardiag validate --dataset DIR: the detectors over a generated dataset (geardiag dataset).
#pragma once

#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "diag/io/recording.hpp"

namespace geardiag {

int validate_dataset(int argc, char** argv);

// geardiag validate --history DIR: every life history of a dataset through `geardiag batch
// --healthy-first` (tools/validate_history.cpp).
int validate_history(int argc, char** argv);

// The rows of DIR/manifest.jsonl (each with at least `file` and `class`). Throws
// diag::InputError naming `option` and DIR, or the manifest's line.
std::vector<nlohmann::json> read_manifest(const std::string& dir, const std::string& option);

// The share of rows with "detected" true against a numeric column, in four equal-width bins over
// the range present (one bin when all are equal): [{from, to, recordings, detected, rate}].
nlohmann::json rate_by(const std::vector<nlohmann::json>& rows, const std::string& column);

// Every recording of a dataset's manifest rows (DIR/<row's file>) through `judge`: each file read
// by `read` on the main thread, in rounds of `jobs` judged on worker threads (run_in_rounds: the
// HDF5 reader forks, which must not happen while other threads run). `judge(i, rec, path)` gets
// the recording, or nullopt when it could not be read, with the reason in `read_error`; the
// recording is released after judge returns. A progress line on a terminal.
using DatasetJudge = std::function<void(std::size_t i, std::optional<diag::Recording>& rec,
                                        const std::string& path, const std::string& read_error)>;
void judge_dataset_recordings(const std::string& dir, const std::vector<nlohmann::json>& rows,
                              int jobs,
                              const std::function<diag::Recording(const std::string&)>& read,
                              const DatasetJudge& judge);

}  // namespace geardiag
