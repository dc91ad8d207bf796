// geardiag validate --dataset DIR: the detectors over a generated dataset (geardiag dataset).
#pragma once

namespace geardiag {

int validate_dataset(int argc, char** argv);

}  // namespace geardiag
