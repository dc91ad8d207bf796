#include "cli_options.hpp"

#include <iostream>
#include <string>

namespace geardiag {

namespace po = boost::program_options;

bool parse_options(int argc, char** argv, const po::options_description& desc,
                   po::variables_map& vm, const po::positional_options_description* positional,
                   const po::options_description* shown) {
  // --help anywhere asks for the help, even where an option would take it as its value
  // (`validate --history --help`).
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::cout << (shown ? *shown : desc) << "\n";
      return false;
    }
  }
  po::command_line_parser parser(argc, argv);
  parser.options(desc);
  if (positional) parser.positional(*positional);
  po::store(parser.run(), vm);
  if (vm.count("help")) {
    std::cout << (shown ? *shown : desc) << "\n";
    return false;
  }
  po::notify(vm);
  return true;
}

}  // namespace geardiag
