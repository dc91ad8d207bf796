// geardiag validate --dataset DIR: the detectors over a generated dataset (geardiag dataset).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace geardiag {

int validate_dataset(int argc, char** argv);

// The share of rows with "detected" true against a numeric column, in four equal-width bins over
// the range present (one bin when all are equal): [{from, to, recordings, detected, rate}].
nlohmann::json rate_by(const std::vector<nlohmann::json>& rows, const std::string& column);

}  // namespace geardiag
