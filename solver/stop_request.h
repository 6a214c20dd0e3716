// Clean stops of a long run: SIGINT (Ctrl-C) and SIGTERM (what `timeout`, systemd and batch
// schedulers send at a job's time limit) ask the analysis to stop at the end of its step
// (DynamicOptions::stop, StaticOptions::stop), so that everything computed is written and the
// program exits with 128 + the signal's number (130, 143): a script tells an interrupted run
// from a finished one. A second signal ends the process at once, as without the handlers.
#pragma once

#include <atomic>

namespace femb {

/// The number of the first SIGINT or SIGTERM received since InstallStopHandlers, or 0.
const std::atomic<int>& StopRequest();

/// Installs the handlers of SIGINT and SIGTERM described above (not for a signal the process
/// was started with ignored: a script's background job, nohup).
void InstallStopHandlers();

}  // namespace femb
