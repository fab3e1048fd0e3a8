#include "util/threads.h"

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cassert>
#include <optional>

namespace lat {

// The control is made in place: oneTBB registers a global_control where it is constructed, and
// a copy (global_control has an implicit copy constructor) is not registered: moving one into
// place leaves no limit at all (so it was from 95efab8 until this file).
struct ThreadLimit::Impl {
    std::optional<tbb::global_control> control;
    int n = 0;

    void set(int threads) {
        control.reset();
        n = threads;
        if (n > 0) control.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(n));
    }
};

namespace {
ThreadLimit::Impl* g_limit = nullptr;  // the command's, while it lives
}

ThreadLimit::ThreadLimit(int n) : impl_(std::make_unique<Impl>()) {
    assert(!g_limit);
    impl_->set(n);
    g_limit = impl_.get();
}

ThreadLimit::~ThreadLimit() { g_limit = nullptr; }

WiderThreads::WiderThreads(int n) {
    if (!g_limit) return;
    previous_ = g_limit->n;
    g_limit->set(n);
}

WiderThreads::~WiderThreads() {
    if (g_limit) g_limit->set(previous_);
}

int core_count() { return tbb::this_task_arena::max_concurrency(); }

int thread_count() {
    return static_cast<int>(std::min<std::size_t>(
        static_cast<std::size_t>(core_count()),
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)));
}

}  // namespace lat
