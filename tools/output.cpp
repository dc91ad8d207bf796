#include "output.hpp"

namespace geardiag {

bool check_output(const std::string& path, const std::string& option) {
  return diag::check_output_path(path, option).kind == diag::OutputKind::kStdout;
}

void write_output(const std::string& path, const std::string& text, const std::string& option) {
  diag::write_output_file(path, text, option);
}

void write_text_atomic(const std::filesystem::path& path, const std::string& text) {
  diag::write_output_file(path, text);
}

void print_warnings(const std::vector<std::string>& warnings, const std::string& command) {
  for (const std::string& w : warnings)
    std::cerr << "geardiag " << command << ": warning: " << w << "\n";
}

}  // namespace geardiag
