#pragma once
// SIGINT and SIGTERM as a request to stop: the handler only records the signal; long loops
// (the renderer's tiles, file writes) poll interrupted() and throw Interrupted, so that the
// stack unwinds, temporary files are removed and the process exits with 128 + the signal.
#include <stdexcept>

namespace lat {

class Interrupted : public std::runtime_error {
public:
    explicit Interrupted(int signal);
    int signal() const { return signal_; }
    int exit_code() const { return 128 + signal_; }  // 130 for SIGINT, 143 for SIGTERM

private:
    int signal_;
};

// Installs the flag-setting handlers for SIGINT and SIGTERM. A second signal while the first
// is still being handled restores the default action, so a repeated Ctrl-C always ends the
// process at once.
void install_interrupt_handlers();

// The signal received since the handlers were installed, or 0. One relaxed atomic load: cheap
// enough to poll per tile or per write.
int interrupt_signal();
inline bool interrupted() {
    return interrupt_signal() != 0;
}
// Throws Interrupted if a signal was received.
void throw_if_interrupted();

// For tests: forgets a received signal.
void clear_interrupt();

}  // namespace lat
