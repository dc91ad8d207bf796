// The geardiag subcommands, one file each. Every command receives its own arguments (argv[0] is
// the subcommand name) and returns the process exit code:
//   0 ok; 1 the analysis found a problem it could not resolve (see each command);
//   2 bad usage or bad input (a message names the file, field and reason); 3 internal error;
//   4 (analyze --fail-on) nothing found, but not every sample of the recording was examined.
#pragma once

namespace geardiag {

inline constexpr int kExitNotExamined = 4;

int cmd_demo(int argc, char** argv);
int cmd_import(int argc, char** argv);
int cmd_info(int argc, char** argv);
int cmd_simulate(int argc, char** argv);
int cmd_sweep(int argc, char** argv);
int cmd_attribute(int argc, char** argv);
int cmd_analyze(int argc, char** argv);
int cmd_validate(int argc, char** argv);
int cmd_profile(int argc, char** argv);
int cmd_wear(int argc, char** argv);
int cmd_dataset(int argc, char** argv);
int cmd_batch(int argc, char** argv);
int cmd_bifurcation(int argc, char** argv);

}  // namespace geardiag
