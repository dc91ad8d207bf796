// geardiag: one binary, git-style subcommands.
#include <boost/program_options/errors.hpp>
#include <cstring>
#include <exception>
#include <iostream>
#include <string>

#include "commands.hpp"
#include "diag/error.hpp"

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**);
  const char* summary;
};

const Command kCommands[] = {
    {"demo", geardiag::cmd_demo, "run the built-in example end to end and print what it found"},
    {"import", geardiag::cmd_import, "convert CSV / WAV / MAT measurements to an HDF5 recording"},
    {"info", geardiag::cmd_info, "describe a recording, or a gearbox description (--gearbox)"},
    {"simulate", geardiag::cmd_simulate, "simulate a gearbox with defects into a recording"},
    {"sweep", geardiag::cmd_sweep, "speed sweep up and down: peak and RMS vs speed, resonances"},
    {"attribute", geardiag::cmd_attribute,
     "attribute defects to gears/shafts from the output shaft's transmission error"},
    {"analyze", geardiag::cmd_analyze,
     "offline analysis of a recording: spectra, TSA, indicators, findings; JSON/HTML reports"},
    {"validate", geardiag::cmd_validate, "closed-loop validation of a detector on your gearbox"},
    {"bifurcation", geardiag::cmd_bifurcation,
     "face-gear pair: Poincare points and period class vs input speed"},
};

void print_usage(std::ostream& os) {
  os << "usage: geardiag <command> [options]   (geardiag <command> --help for its options)\n\n"
        "commands:\n";
  for (const auto& c : kCommands) {
    os << "  " << c.name << std::string(12 - std::strlen(c.name), ' ') << c.summary << "\n";
  }
  os << "\nexit codes: 0 ok, 1 unresolved finding, 2 bad usage or input, 3 internal error\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    print_usage(std::cerr);
    return 2;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    print_usage(std::cout);
    return 0;
  }
  if (name == "--version") {
    std::cout << "geardiag " << GEARDIAG_VERSION << " (" << GEARDIAG_GIT_REVISION << ")\n";
    return 0;
  }
  for (const auto& c : kCommands) {
    if (name != c.name) continue;
    try {
      return c.run(argc - 1, argv + 1);
    } catch (const diag::InputError& e) {
      std::cerr << "geardiag " << name << ": error: " << e.what() << "\n";
      return 2;
    } catch (const boost::program_options::error& e) {
      std::cerr << "geardiag " << name << ": usage error: " << e.what() << " (see geardiag " << name
                << " --help)\n";
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "geardiag " << name << ": internal error: " << e.what() << "\n";
      return 3;
    }
  }
  std::cerr << "geardiag: unknown command '" << name << "'\n\n";
  print_usage(std::cerr);
  return 2;
}
