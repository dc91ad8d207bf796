#include "diag/io/json_fields.hpp"

#include <fstream>
#include <sstream>

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
  const std::string where = path.string();
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec)) {
    const auto size = std::filesystem::file_size(path, ec);
    if (!ec && size > kMaxJsonBytes) {
      throw InputError(format_error(where, "",
                                    std::to_string(size) + " bytes; a JSON description may have " +
                                        "at most " + std::to_string(kMaxJsonBytes)));
    }
  } else if (std::filesystem::is_directory(path, ec)) {
    throw InputError(format_error(where, "", "is a directory, not a JSON file"));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(format_error(where, "", "cannot open the file"));
  std::string text;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    text.append(buf, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxJsonBytes) {
      throw InputError(
          format_error(where, "", "more than " + std::to_string(kMaxJsonBytes) + " bytes of JSON"));
    }
  }
  if (text.empty()) throw InputError(format_error(where, "", "the file is empty"));
  return parse_json_text(text, where);
}

}  // namespace diag
