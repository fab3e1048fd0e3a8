#include "util/progress.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <mutex>

namespace lat {
namespace {

std::mutex g_sink_mutex;
ProgressSink g_sink;

ProgressSink current_sink() {
    const std::lock_guard lock(g_sink_mutex);
    return g_sink;
}

}  // namespace

void set_progress_sink(ProgressSink sink) {
    const std::lock_guard lock(g_sink_mutex);
    g_sink = std::move(sink);
}

bool ProgressBar::stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(std::string label, std::uint64_t total, bool enabled, int delay_ms)
    : label_(std::move(label)), total_(total == 0 ? 1 : total), enabled_(enabled), delayed_(delay_ms > 0) {
    if (!enabled_) return;
    thread_ = std::thread([this, delay_ms] {
        for (int waited = 0; waited < delay_ms && !stop_.load(); waited += 10)
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        while (!stop_.load()) {
            draw(false);
            drawn_ = true;
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
    });
}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::finish() {
    if (!enabled_ || stop_.exchange(true)) return;
    thread_.join();
    if (drawn_ || !delayed_) draw(true);
}

void ProgressBar::draw(bool final) const {
    const double frac = final ? 1.0 : static_cast<double>(done_.load()) / static_cast<double>(total_);
    if (const ProgressSink sink = current_sink()) {
        sink(label_, frac);
        return;
    }
    constexpr int kWidth = 40;
    const int filled = static_cast<int>(frac * kWidth);
    char bar[kWidth + 1];
    for (int i = 0; i < kWidth; ++i) bar[i] = i < filled ? '#' : '.';
    bar[kWidth] = 0;
    std::fprintf(stderr, "\r%s [%s] %3d%%%s", label_.c_str(), bar, static_cast<int>(frac * 100),
                 final ? "\r\033[K" : "");
    std::fflush(stderr);
}

}  // namespace lat
