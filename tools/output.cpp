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

}  // namespace geardiag
