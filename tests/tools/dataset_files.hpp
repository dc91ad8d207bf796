// The dataset CLI tests' shared setup (dataset_cli_test.cpp, dataset_modes_cli_test.cpp): spec
// files written as text, the test gearboxes, a file's bytes, a dataset folder's files and its
// manifest rows.
#pragma once

#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace cli_test {

// A gearbox description of testdata/gearbox.
inline std::filesystem::path testdata_gearbox(const std::string& name) {
  return std::filesystem::path(GEARDIAG_TESTDATA_DIR) / "gearbox" / name;
}

// Writes `text` to `path` (a spec, a gearbox description) and returns the path.
inline std::filesystem::path write_text(const std::filesystem::path& path,
                                        const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Every file of a dataset folder (relative name -> bytes), the lock file left out.
inline std::map<std::string, std::string> folder_files(const std::filesystem::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file() || e.path().filename() == ".lock") continue;
    out[std::filesystem::relative(e.path(), dir).string()] = slurp(e.path());
  }
  return out;
}

// The rows of the folder's manifest.jsonl, in order.
inline std::vector<nlohmann::json> manifest_rows(const std::filesystem::path& dir) {
  std::vector<nlohmann::json> rows;
  std::ifstream in(dir / "manifest.jsonl");
  for (std::string line; std::getline(in, line);) rows.push_back(nlohmann::json::parse(line));
  return rows;
}

}  // namespace cli_test
