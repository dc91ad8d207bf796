#include "diag/error.hpp"

namespace diag {

std::string format_error(const std::string& where, const std::string& field,
                         const std::string& reason) {
  std::string out;
  for (const std::string* part : {&where, &field, &reason}) {
    if (part->empty()) continue;
    if (!out.empty()) out += ": ";
    out += *part;
  }
  return out;
}

}  // namespace diag
