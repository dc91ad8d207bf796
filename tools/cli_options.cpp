#include "cli_options.hpp"

#include <iostream>

namespace geardiag {

namespace po = boost::program_options;

bool parse_options(int argc, char** argv, const po::options_description& desc,
                   po::variables_map& vm, const po::positional_options_description* positional,
                   const po::options_description* shown) {
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
