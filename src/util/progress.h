#pragma once
// A progress bar on stderr, redrawn by its own thread while work runs; silent when stderr is
// not a terminal.
#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

namespace lat {

class ProgressBar {
public:
    ProgressBar(std::string label, std::uint64_t total, bool enabled);
    ~ProgressBar();  // finishes the bar
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    void add(std::uint64_t n) { done_.fetch_add(n, std::memory_order_relaxed); }
    void finish();

    static bool stderr_is_terminal();

private:
    std::string label_;
    std::uint64_t total_;
    bool enabled_;
    std::atomic<std::uint64_t> done_{0};
    std::atomic<bool> stop_{false};
    std::thread thread_;

    void draw(bool final) const;
};

}  // namespace lat
