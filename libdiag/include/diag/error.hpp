// Errors shared by every part of geardiag.
//
// Two kinds of failure (STYLE.md, practice 7):
//  - InputError: bad input or a broken precondition that the user can fix (a file, a field, an
//    option). The message names the file or function, the field, the value and the valid range.
//    The CLI maps it to exit code 2.
//  - anything else derived from std::exception is an internal error: exit code 3.
// Expected outcomes (no defect found, periods not separable) are data in results, never errors.
#pragma once

#include <stdexcept>
#include <string>

namespace diag {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// Builds "where: field: reason" with empty parts left out.
std::string format_error(const std::string& where, const std::string& field,
                         const std::string& reason);

// Throws InputError("where: field: reason").
[[noreturn]] inline void fail(const std::string& where, const std::string& field,
                              const std::string& reason) {
  throw InputError(format_error(where, field, reason));
}
// Checks in loops over samples use `if (!ok) fail(...)` so the message is built only on failure.
inline void require(bool ok, const std::string& where, const std::string& field,
                    const std::string& reason) {
  if (!ok) fail(where, field, reason);
}

}  // namespace diag
