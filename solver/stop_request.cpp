#include "solver/stop_request.h"

#include <csignal>

namespace femb {

namespace {

std::atomic<int> g_stop{0};
static_assert(std::atomic<int>::is_always_lock_free, "the stop request is written from a signal handler");

extern "C" void OnStopSignal(int signal) {
  if (g_stop.load() != 0) {  // the second one: the default action, at once
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  g_stop.store(signal);
}

}  // namespace

const std::atomic<int>& StopRequest() { return g_stop; }

void InstallStopHandlers() {
  struct sigaction action = {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  for (int signal : {SIGINT, SIGTERM}) {
    // A signal the parent ignores stays ignored (a background job of a script, nohup).
    struct sigaction old = {};
    sigaction(signal, nullptr, &old);
    if (old.sa_handler != SIG_IGN) sigaction(signal, &action, nullptr);
  }
}

}  // namespace femb
