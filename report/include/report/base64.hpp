// Base64 (RFC 4648, section 4: the standard alphabet, '=' padding, no line breaks), for the
// data: URIs of images inlined in the HTML report.
#pragma once

#include <string>

namespace report {

// "Man" -> "TWFu", "Ma" -> "TWE=", "" -> "".
std::string base64(const std::string& d);

}  // namespace report
