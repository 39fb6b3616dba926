#include "monomap/exe/interrupt.h"

#include <pthread.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "monomap/util/file.h"

namespace monomap {

void InstallInterruptCleanup() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  // Blocked everywhere, taken by sigwait in one thread: the cleanup runs in
  // a normal context, not in a signal handler.
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread([set]() {
    int sig = 0;
    if (sigwait(&set, &sig) != 0) return;
    RemoveRegisteredTemporaries();
    std::fprintf(stderr,
                 "monomap: interrupted by %s; temporary output removed\n",
                 strsignal(sig));
    std::_Exit(128 + sig);
  }).detach();
}

}  // namespace monomap
