// The program's version and the git revision it was built from (CMake writes both into one
// generated source, so that a new revision recompiles that file only).
#pragma once

namespace diag {

const char* version();       // PROJECT_VERSION, e.g. "0.6.0"
const char* git_revision();  // `git rev-parse --short=12 HEAD` at configure time, else "unknown"

}  // namespace diag
