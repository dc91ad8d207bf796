#include "diag/io/json_fields.hpp"

#include <sstream>

#include "diag/io/input_file.hpp"

namespace diag {

namespace {

// Deepest nesting of arrays/objects in `text`, outside strings; stops counting past `limit`.
int nesting_depth(const std::string& text, int limit) {
  int depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) return deepest;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

}  // namespace

nlohmann::json parse_json_text(const std::string& text, const std::string& where) {
  if (text.size() > kMaxJsonBytes) {
    throw InputError(format_error(where, "",
                                  std::to_string(text.size()) + " bytes of JSON; at most " +
                                      std::to_string(kMaxJsonBytes) + " are read"));
  }
  if (nesting_depth(text, kMaxJsonDepth) > kMaxJsonDepth) {
    throw InputError(format_error(
        where, "", "nested more than " + std::to_string(kMaxJsonDepth) + " levels deep"));
  }
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(format_error(where, "", std::string("not valid JSON: ") + e.what()));
  }
}

nlohmann::json load_json_file(const std::filesystem::path& path) {
  // Regular files only (a FIFO or device would hang the read), no NUL byte, bounded size
  // (input_file.hpp).
  return parse_json_text(read_input_file(path, {}, kMaxJsonBytes), path.string());
}

}  // namespace diag
