#include "dist/deal.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

#include "dist/job.h"
#include "dist/timeline.h"
#include "dist/transport.h"
#include "util/progress.h"
#include "util/threads.h"

namespace lat::dist {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

// A chunk is at least one item per thread of the rank that asks, else its share of what is
// left divided by kGuide: big chunks first (few messages), small ones last (even finish).
constexpr std::uint64_t kGuide = 4;

// The items dealt to this rank and not started yet. Its threads take them one by one; the main
// thread (which alone talks to the other ranks) refills it when it runs low.
class ChunkQueue {
public:
    explicit ChunkQueue(std::uint64_t low) : low_(low) {}

    void push(Chunk c) {
        const std::lock_guard lock(m_);
        chunks_.push_back(c);
        queued_ += c.end - c.begin;
        work_.notify_all();
    }
    // No more chunks will come (or a thread failed): waiting threads return.
    void close() {
        const std::lock_guard lock(m_);
        closed_ = true;
        work_.notify_all();
        main_.notify_one();
    }
    // The next item, waiting for one to be dealt; false when there will be none.
    bool pop(std::uint32_t& item, double& waited) {
        std::unique_lock lock(m_);
        if (queued_ == 0 && !closed_) {
            const auto t0 = Clock::now();
            work_.wait(lock, [&] { return queued_ > 0 || closed_; });
            waited += seconds_since(t0);
        }
        if (queued_ == 0 || failed_) return false;
        Chunk& c = chunks_.front();
        item = c.begin++;
        if (c.begin == c.end) chunks_.pop_front();
        if (--queued_ <= low_) main_.notify_one();
        return true;
    }
    void fail() {
        const std::lock_guard lock(m_);
        failed_ = true;
        chunks_.clear();
        queued_ = 0;
        closed_ = true;
        work_.notify_all();
    }
    // The threads are done: wakes the main thread.
    void finish() {
        const std::lock_guard lock(m_);
        finished_ = true;
        main_.notify_one();
    }
    bool low() {
        const std::lock_guard lock(m_);
        return !closed_ && queued_ <= low_;
    }
    bool finished() {
        const std::lock_guard lock(m_);
        return finished_;
    }
    // The main thread sleeps until the queue runs low, the threads finish, or `ns` pass.
    void wait(long ns) {
        std::unique_lock lock(m_);
        main_.wait_for(lock, std::chrono::nanoseconds(ns),
                       [&] { return finished_ || (!closed_ && queued_ <= low_); });
    }

private:
    std::mutex m_;
    std::condition_variable work_, main_;
    std::deque<Chunk> chunks_;
    std::uint64_t queued_ = 0;
    const std::uint64_t low_;
    bool closed_ = false, failed_ = false, finished_ = false;
};

DealReport deal_here(std::uint32_t n, const std::function<void(std::uint32_t)>& work,
                     const DealOptions& opt) {
    DealReport report;
    report.threads = thread_count();
    const auto t0 = Clock::now();
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, n, 1), [&](const auto& range) {
        for (std::uint32_t i = range.begin(); i != range.end(); ++i) {
            work(i);
            if (opt.progress) opt.progress->add(1);
        }
    });
    report.chunks = {{0, n}};
    report.items = n;
    report.seconds = seconds_since(t0);
    return report;
}

// One rank's part in a dealt loop: its threads work through a ChunkQueue while the main thread
// deals (rank 0) or asks for chunks (the others).
class Dealer {
public:
    Dealer(std::uint32_t n, const std::function<void(std::uint32_t)>& work, const DealOptions& opt)
        : n_(n), work_(work), opt_(opt), threads_(thread_count()),
          queue_(2 * static_cast<std::uint64_t>(threads_)) {
        report_.threads = threads_;
        std::vector<int> all(static_cast<std::size_t>(ranks()));
        transport::allgather(&threads_, sizeof threads_, all.data());
        for (const int t : all) total_threads_ += static_cast<std::uint64_t>(t);
    }

    DealReport run() {
        const auto t0 = Clock::now();
        std::thread workers([&] { work_here(); });
        try {
            if (is_root()) deal(); else ask();
        } catch (...) {
            queue_.fail();
            workers.join();
            throw;
        }
        workers.join();
        if (error_) std::rethrow_exception(error_);
        report_.seconds = seconds_since(t0);
        report_.wait_seconds = waited_.load();
        return std::move(report_);
    }

private:
    const std::uint32_t n_;
    const std::function<void(std::uint32_t)>& work_;
    const DealOptions& opt_;
    const int threads_;
    std::uint64_t total_threads_ = 0;
    ChunkQueue queue_;
    DealReport report_;
    std::atomic<std::uint64_t> done_{0};
    std::atomic<double> waited_{0};
    std::exception_ptr error_;
    std::uint32_t next_ = 0;  // rank 0: items dealt so far

    // On this rank's threads (a oneTBB loop with one body per thread, each taking items).
    void work_here() {
        try {
            tbb::parallel_for(
                tbb::blocked_range<int>(0, threads_, 1),
                [&](const tbb::blocked_range<int>&) {
                    double waited = 0;
                    std::uint32_t i = 0;
                    try {
                        while (queue_.pop(i, waited)) {
                            work_(i);
                            done_.fetch_add(1, std::memory_order_relaxed);
                            if (opt_.progress && is_root()) opt_.progress->add(1);
                        }
                    } catch (...) {
                        queue_.fail();  // the other threads stop too, instead of waiting
                        throw;
                    }
                    waited_.fetch_add(waited);
                },
                tbb::simple_partitioner());
        } catch (...) {
            error_ = std::current_exception();
        }
        queue_.finish();
    }

    Chunk take(std::uint64_t threads) {
        const std::uint64_t left = n_ - next_;
        const std::uint64_t size =
            std::min(left, std::max(threads, left * threads / (kGuide * total_threads_)));
        const Chunk c{next_, next_ + static_cast<std::uint32_t>(size)};
        next_ = c.end;
        return c;
    }

    // Rank 0: answers every request, and keeps its own queue filled, until every rank has been
    // told there is nothing left and its own threads are done.
    void deal() {
        int told_done = 0;
        bool closed = false;
        for (int idle = 0;; ++idle) {
            int from = 0;
            while (transport::poll(transport::kDealRequest, from)) {
                std::uint32_t request[2];  // the asker's threads, items done since it last asked
                transport::receive(from, transport::kDealRequest, request, sizeof request);
                if (opt_.progress) opt_.progress->add(request[1]);
                const Chunk c = take(request[0]);
                const std::uint32_t reply[2] = {c.begin, c.end};
                transport::send(from, transport::kDealReply, reply, sizeof reply);
                if (c.begin == c.end) ++told_done;
                idle = 0;
            }
            if (!closed && queue_.low()) {
                const Chunk c = take(static_cast<std::uint64_t>(threads_));
                if (c.begin == c.end) {
                    queue_.close();
                    closed = true;
                } else {
                    queue_.push(c);
                    report_.chunks.push_back(c);
                    report_.items += c.end - c.begin;
                }
                idle = 0;
            }
            if (queue_.finished() && (error_ || (closed && told_done == ranks() - 1))) return;
            queue_.wait(transport::idle_pause_ns(idle));
        }
    }

    // Other ranks: one request at a time, sent while the queue still holds two rounds of items
    // (rank 0 may take up to a millisecond to answer).
    void ask() {
        bool asked = false, closed = false;
        std::uint64_t reported = 0;
        for (int idle = 0;; ++idle) {
            int from = 0;
            if (asked && transport::poll(transport::kDealReply, from)) {
                std::uint32_t reply[2];
                transport::receive(0, transport::kDealReply, reply, sizeof reply);
                asked = false;
                idle = 0;
                if (reply[0] == reply[1]) {
                    queue_.close();
                    closed = true;
                } else {
                    queue_.push({reply[0], reply[1]});
                    report_.chunks.push_back({reply[0], reply[1]});
                    report_.items += reply[1] - reply[0];
                }
            }
            if (!asked && !closed && queue_.low()) {
                const std::uint64_t done = done_.load();
                const std::uint32_t request[2] = {static_cast<std::uint32_t>(threads_),
                                                  static_cast<std::uint32_t>(done - reported)};
                reported = done;
                transport::send(0, transport::kDealRequest, request, sizeof request);
                asked = true;
                idle = 0;
            }
            if (queue_.finished()) return;
            if (asked) transport::idle_wait(idle);
            else queue_.wait(10'000'000);
        }
    }
};

}  // namespace

DealReport deal(std::uint32_t n, const std::function<void(std::uint32_t)>& work, const DealOptions& options) {
    DealReport report = !options.across_ranks || !distributed() ? deal_here(n, work, options)
                                                                : Dealer(n, work, options).run();
    mark(Step::kDealt);
    return report;
}

}  // namespace lat::dist
