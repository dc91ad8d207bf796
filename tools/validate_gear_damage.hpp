// geardiag validate --gear-damage: the closed simulate -> locate loop of the damaged-shaft
// locator on the user's gearbox(es), with realistic gears (ISO 1328 pitch errors, runout).
#pragma once

namespace geardiag {

// argv as cmd_validate's (argv[0] the subcommand name). Exit 0; 1 when the locator's claims are
// not to be trusted on these gearboxes (false alarms above 5 % of the healthy cases or wrong
// shafts above 5 % of the faulty ones); 2 bad usage.
int validate_gear_damage(int argc, char** argv);

}  // namespace geardiag
