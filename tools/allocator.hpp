// The allocator settings of the commands that analyse recordings (analyze, batch): see
// allocator.cpp for what they change and the measurements behind them.
#pragma once

namespace geardiag {

// Keeps freed record-length buffers in the process for the next one, and backs the heap with
// transparent huge pages where the kernel offers them. Process-wide: called by the commands only,
// never by the library. Harmless where glibc or Linux is absent (it then does nothing).
void tune_allocator_for_recordings();

}  // namespace geardiag
