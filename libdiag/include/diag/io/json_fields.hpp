// Strict reading of JSON objects for descriptions (gearbox, scenario): unknown keys are refused
// with the list of allowed ones, and every error names "where: path.key: reason".
//
// Reading JSON text from a file (parse_json_text, load_json_file) is bounded: at most
// kMaxJsonBytes of text and kMaxJsonDepth levels of nesting, checked by a scan before the parser
// runs (nlohmann's parser is iterative, but dump() and the readers recurse, so a description
// nested 20 000 levels deep would overflow the stack later). Every parser exception (syntax, a
// number beyond double range such as 1e400, invalid UTF-8) becomes an InputError naming `where`.
#pragma once

#include <cctype>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <string_view>

#include "diag/error.hpp"
#include "diag/util/number_format.hpp"

namespace diag {

inline constexpr std::size_t kMaxJsonBytes = 64u << 20;  // 64 MiB of JSON text
inline constexpr int kMaxJsonDepth = 64;                 // nested arrays/objects

// Parses JSON text within the limits above; throws InputError("where: ...") otherwise.
nlohmann::json parse_json_text(const std::string& text, const std::string& where);
// Reads and parses a file (where = the path); refuses a missing, unreadable, empty or too large
// file before reading it.
nlohmann::json load_json_file(const std::filesystem::path& path);

// Reads typed fields of one JSON object, naming "where: path.key" in every error.
class Fields {
 public:
  Fields(const nlohmann::json& obj, std::string where, std::string path,
         std::set<std::string> allowed)
      : obj_(obj), where_(std::move(where)), path_(std::move(path)) {
    if (!obj_.is_object()) fail("", "must be a JSON object");
    for (const auto& [key, value] : obj_.items()) {
      if (key == "comment") {
        // Free text: a string or an array of strings, nothing nested.
        bool ok = value.is_string();
        if (value.is_array()) {
          ok = true;
          for (const auto& v : value) ok &= v.is_string();
        }
        if (!ok) fail(key, "must be a string or an array of strings");
        continue;
      }
      if (key.empty() || key[0] == '_' || allowed.count(key)) continue;
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(key, "unknown field (allowed: " + list + ")");
    }
  }

  [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
    std::string field = path_;
    if (!key.empty()) field += (field.empty() ? "" : ".") + key;
    throw InputError(format_error(where_, field, reason));
  }

  bool has(const std::string& key) const { return obj_.contains(key) && !obj_[key].is_null(); }

  std::string str(const std::string& key) const {
    if (!has(key)) fail(key, "required string is missing");
    if (!obj_[key].is_string()) fail(key, "must be a string");
    const std::string v = obj_[key].get<std::string>();
    if (v.empty()) fail(key, "must not be empty");
    return v;
  }
  // A name that becomes part of channel and dataset names: letters, digits, space, '_', '-',
  // '+', '(', ')', ':', '#' only (no '/', '.', control characters or NUL), at most 64 bytes.
  std::string name(const std::string& key) const {
    const std::string v = str(key);
    if (v.size() > 64) fail(key, "must be at most 64 characters");
    for (char c : v) {
      const bool ok = std::isalnum(static_cast<unsigned char>(c)) ||
                      std::string_view(" _-+():#").find(c) != std::string_view::npos;
      if (!ok) {
        fail(key, "'" + printable(v) +
                      "' may hold only letters, digits, space and _-+():# (it names channels "
                      "and datasets)");
      }
    }
    return v;
  }
  // Free text shown to the user (a gearbox's name): no control characters or NUL, at most 200
  // bytes.
  std::string label(const std::string& key) const {
    const std::string v = str(key);
    if (v.size() > 200) fail(key, "must be at most 200 characters");
    for (unsigned char c : v) {
      if (c < 0x20 || c == 0x7f) fail(key, "'" + printable(v) + "' holds a control character");
    }
    return v;
  }
  std::string str(const std::string& key, const std::string& dflt) const {
    return has(key) ? str(key) : dflt;
  }

  double num(const std::string& key) const {
    if (!has(key)) fail(key, "required number is missing");
    if (!obj_[key].is_number()) fail(key, "must be a number");
    const double v = obj_[key].get<double>();
    if (!std::isfinite(v)) fail(key, "must be finite");
    return v;
  }
  double num(const std::string& key, double dflt) const { return has(key) ? num(key) : dflt; }
  double positive(const std::string& key) const { return check_pos(key, num(key)); }
  double positive(const std::string& key, double dflt) const {
    return has(key) ? check_pos(key, num(key)) : dflt;
  }
  double non_negative(const std::string& key, double dflt) const {
    const double v = num(key, dflt);
    if (v < 0) fail(key, "must be >= 0 (got " + diag::format_significant(v, 6) + ")");
    return v;
  }

  int integer(const std::string& key) const {
    if (!has(key)) fail(key, "required integer is missing");
    const nlohmann::json& v = obj_[key];
    if (!v.is_number_integer()) {
      if (v.is_number_float() && std::floor(v.get<double>()) == v.get<double>() &&
          std::abs(v.get<double>()) < 1e9) {
        return static_cast<int>(v.get<double>());
      }
      fail(key, "must be an integer");
    }
    const auto i = v.get<long long>();
    if (i < -1000000000LL || i > 1000000000LL) fail(key, "out of range");
    return static_cast<int>(i);
  }

  bool boolean(const std::string& key, bool dflt) const {
    if (!has(key)) return dflt;
    if (!obj_[key].is_boolean()) fail(key, "must be true or false");
    return obj_[key].get<bool>();
  }

  // The value as it is, for the caller to check. A missing key is refused naming it (const
  // operator[] on a missing key is undefined behaviour in nlohmann::json: libFuzzer found a
  // profile defect without roll_deg reading freed memory).
  const nlohmann::json& raw(const std::string& key) const {
    if (!obj_.contains(key)) fail(key, "required field is missing");
    return obj_[key];
  }
  const std::string& where() const { return where_; }
  std::string sub(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  // v with control characters shown as \xNN.
  static std::string printable(const std::string& v) {
    std::string out;
    for (unsigned char c : v) {
      if (c < 0x20 || c == 0x7f) {
        static const char* kHex = "0123456789abcdef";
        out += "\\x";
        out += kHex[c >> 4];
        out += kHex[c & 15];
      } else {
        out += static_cast<char>(c);
      }
    }
    return out;
  }

 private:
  double check_pos(const std::string& key, double v) const {
    if (!(v > 0)) fail(key, "must be > 0 (got " + diag::format_significant(v, 6) + ")");
    return v;
  }
  const nlohmann::json& obj_;
  std::string where_, path_;
};

}  // namespace diag
