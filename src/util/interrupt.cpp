#include "util/interrupt.h"

#include <signal.h>
#include <atomic>

#include <csignal>
#include <string>

namespace lat {
namespace {

// Written by the signal handler: a lock-free atomic is async-signal-safe.
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void on_signal(int sig) {
    int expected = 0;
    if (!g_signal.compare_exchange_strong(expected, sig, std::memory_order_relaxed)) {
        // Asked again before we got round to stopping: give up on a tidy exit.
        std::signal(sig, SIG_DFL);
        std::raise(sig);
    }
}

}  // namespace

Interrupted::Interrupted(int signal)
    : std::runtime_error(signal == SIGTERM ? "terminated" : "interrupted"), signal_(signal) {}

void install_interrupt_handlers() {
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;  // reads and writes carry on; the loops poll the flag
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

int interrupt_signal() {
    return g_signal.load(std::memory_order_relaxed);
}

void throw_if_interrupted() {
    if (const int sig = interrupt_signal(); sig != 0) throw Interrupted(sig);
}

void clear_interrupt() {
    g_signal.store(0, std::memory_order_relaxed);
}

}  // namespace lat
