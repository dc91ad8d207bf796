#include "output.hpp"

#include <fstream>
#include <system_error>
#include <unistd.h>

#include "diag/error.hpp"

namespace geardiag {

void write_text_atomic(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path tmp = path.string() + ".tmp-" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw diag::InputError(path.string() + ": cannot write the file");
    out << text;
    out.flush();
    if (!out) {
      out.close();
      std::filesystem::remove(tmp);
      throw diag::InputError(path.string() + ": write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw diag::InputError(path.string() +
                           ": cannot rename the temporary file into place: " + ec.message());
  }
}


}  // namespace geardiag
