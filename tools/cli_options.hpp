// The one way every subcommand reads its options (Boost.ProgramOptions).
#pragma once

#include <boost/program_options.hpp>

namespace geardiag {

// Parses argv against `desc` (and the positional names, when given) into `vm`. With --help it
// prints `shown` (when given: the visible part of `desc`), else `desc`, to stdout and returns false
// (the command then exits 0); otherwise it checks the
// required options (po::notify) and returns true. Unknown or malformed options throw
// po::error, which main() turns into a usage error (exit 2).
bool parse_options(
    int argc, char** argv, const boost::program_options::options_description& desc,
    boost::program_options::variables_map& vm,
    const boost::program_options::positional_options_description* positional = nullptr,
    const boost::program_options::options_description* shown = nullptr);

}  // namespace geardiag
