#pragma once
// A progress bar on stderr, redrawn by its own thread while work runs; silent when stderr is
// not a terminal.
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>

namespace lat {

// Where enabled bars report instead of stderr, for a program that embeds the renderer (the Python
// module's progress callback): called from a bar's own thread about ten times a second with its
// label and the share done, 0..1, and once with 1 when it finishes. Empty: stderr.
using ProgressSink = std::function<void(const std::string& label, double done)>;
void set_progress_sink(ProgressSink sink);

class ProgressBar {
public:
    // delay_ms: the bar is drawn only once the work has taken that long (work that ends
    // sooner shows nothing).
    ProgressBar(std::string label, std::uint64_t total, bool enabled, int delay_ms = 0);
    ~ProgressBar();  // finishes the bar
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    void add(std::uint64_t n) { done_.fetch_add(n, std::memory_order_relaxed); }
    void set(std::uint64_t n) { done_.store(n, std::memory_order_relaxed); }
    void finish();

    static bool stderr_is_terminal();

private:
    std::string label_;
    std::uint64_t total_;
    bool enabled_;
    bool delayed_;
    std::atomic<std::uint64_t> done_{0};
    std::atomic<bool> stop_{false};
    std::atomic<bool> drawn_{false};
    std::thread thread_;

    void draw(bool final) const;
};

}  // namespace lat
