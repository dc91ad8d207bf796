// geardiag validate --dataset on a kinematic dataset: the period matcher's findings against the
// manifest's defects, right / partial / silent / wrong per class (validate_kinematic.cpp).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace geardiag {

// rows: the manifest's rows (each gains its verdict). Prints the table; writes --json / --html.
int validate_kinematic_dataset(const std::string& dir, std::vector<nlohmann::json>& rows,
                               const std::string& json_out, const std::string& html_out, int jobs);

}  // namespace geardiag
