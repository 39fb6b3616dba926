// SIGINT, SIGTERM and SIGHUP end monomap cleanly: the temporary output
// directories of the run are removed before the process exits.
#pragma once

namespace monomap {

// Blocks the signals in the calling thread (and so in every thread it
// starts later) and starts a thread that waits for them, removes the
// registered temporaries (util/file.h) and exits with 128 + signal. Call
// first thing in main(), before any other thread exists.
void InstallInterruptCleanup();

}  // namespace monomap
