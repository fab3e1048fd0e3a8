#include "distributed/deal.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <deque>
#include <mutex>

#include "distributed/job.h"
#include "distributed/timeline.h"
#include "distributed/transport.h"
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

// See Dealer::keep().
constexpr double kLeadSeconds = 0.004;
constexpr std::uint64_t kLeadRounds = 8;

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

// One rank's part in a dealt loop. Its threads take items from a queue of dealt chunks; between
// two items, whichever thread gets the message lock talks to the other ranks (MPI_THREAD_
// SERIALIZED): rank 0 answers requests and refills its own queue, the others ask for their
// next chunk. So no thread wakes up only to poll: on a node whose cores all render, a polling
// thread would take its core from a renderer a thousand times a second.
class Dealer {
public:
    Dealer(std::uint32_t n, const std::function<void(std::uint32_t)>& work, const DealOptions& opt)
        : n_(n), work_(work), opt_(opt), threads_(thread_count()) {
        report_.threads = threads_;
        std::vector<int> all(static_cast<std::size_t>(ranks()));
        transport::allgather(&threads_, sizeof threads_, all.data());
        for (const int t : all) total_threads_ += static_cast<std::uint64_t>(t);
        // Every rank's first chunk, rank by rank, as rank 0 would deal them: each rank works
        // out its own, so no rank waits for an answer at the start.
        for (std::size_t r = 0; r < all.size(); ++r) {
            const Chunk c = take(static_cast<std::uint64_t>(all[r]));
            if (static_cast<int>(r) == rank()) push(c);
            if (r > 0 && c.begin == c.end) ++told_done_;  // it knows: it will not ask
        }
    }

    DealReport run() {
        t0_ = Clock::now();
        tbb::parallel_for(
            tbb::blocked_range<int>(0, threads_, 1),
            [&](const tbb::blocked_range<int>&) { work_here(); }, tbb::simple_partitioner());
        report_.seconds = seconds_since(t0_);
        // Rank 0 answers the last requests (each told there is nothing left) after its own
        // items: the others may still be finishing theirs.
        if (is_root())
            for (int idle = 0; told_done_ < ranks() - 1; ++idle) {
                if (answer_requests()) idle = 0;
                transport::idle_wait(idle);
            }
        report_.wait_seconds = waited_.load();
        return std::move(report_);
    }

private:
    const std::uint32_t n_;
    const std::function<void(std::uint32_t)>& work_;
    const DealOptions& opt_;
    const int threads_;
    std::uint64_t total_threads_ = 0;
    Clock::time_point t0_;
    DealReport report_;  // chunks and items: written by push()
    std::atomic<std::uint64_t> done_{0};
    std::atomic<double> waited_{0};

    // The queue of items dealt here and not started (under queue_).
    std::mutex queue_;
    std::deque<Chunk> chunks_;
    std::uint64_t queued_ = 0;
    bool closed_ = false;  // no more chunks will come
    std::atomic<bool> failed_{false};

    // The message lock: only its holder calls MPI, and only it touches what follows.
    std::mutex talk_;
    std::uint32_t next_ = 0;  // rank 0: items dealt so far (elsewhere: only the first round)
    int told_done_ = 0;       // rank 0: ranks told there is nothing left
    bool asked_ = false;      // other ranks: a request is waiting for its answer
    std::uint64_t reported_ = 0;  // other ranks: items done, as told to rank 0 so far

    // One body per thread: items until none are left, talking between them.
    void work_here() {
        double waited = 0;
        try {
            for (int idle = 0;;) {
                talk();
                std::uint32_t i = 0;
                bool closed = false;
                if (pop(i, closed)) {
                    work_(i);
                    done_.fetch_add(1, std::memory_order_relaxed);
                    if (opt_.progress && is_root()) opt_.progress->add(1);
                    idle = 0;
                    continue;
                }
                if (closed || failed_) break;
                // Nothing here yet: a chunk is on its way (another thread may hold the lock).
                const auto w0 = Clock::now();
                transport::idle_wait(idle++);
                waited += seconds_since(w0);
            }
        } catch (...) {
            failed_ = true;  // the other threads stop too, instead of waiting
            waited_.fetch_add(waited);
            throw;
        }
        waited_.fetch_add(waited);
    }

    bool pop(std::uint32_t& item, bool& closed) {
        const std::lock_guard lock(queue_);
        closed = closed_;
        if (queued_ == 0 || failed_) return false;
        Chunk& c = chunks_.front();
        item = c.begin++;
        if (c.begin == c.end) chunks_.pop_front();
        --queued_;
        return true;
    }

    // A dealt chunk into the queue (empty: there will be no more). Callers hold talk_, or are
    // the constructor: report_ is theirs.
    void push(Chunk c) {
        const std::lock_guard lock(queue_);
        if (c.begin == c.end) {
            closed_ = true;  // the dealer has no items left
            return;
        }
        report_.chunks.push_back(c);
        report_.items += c.end - c.begin;
        chunks_.push_back(c);
        queued_ += c.end - c.begin;
    }

    // Whether this rank holds at most `keep` items not started (and more may come).
    bool low(std::uint64_t keep) {
        const std::lock_guard lock(queue_);
        return !closed_ && queued_ <= keep;
    }

    // One round of messages, by whichever thread gets the lock first; the others go on working.
    void talk() {
        std::unique_lock lock(talk_, std::try_to_lock);
        if (!lock.owns_lock()) return;
        if (is_root()) {
            answer_requests();
            // Its own chunk, taken when the last round of items has started.
            const auto threads = static_cast<std::uint64_t>(threads_);
            if (low(threads)) push(take(threads));
        } else {
            ask();
        }
    }

    Chunk take(std::uint64_t threads) {
        const std::uint64_t left = n_ - next_;
        const std::uint64_t size =
            std::min(left, std::max(threads, left * threads / (kGuide * total_threads_)));
        const Chunk c{next_, next_ + static_cast<std::uint32_t>(size)};
        next_ = c.end;
        return c;
    }

    // Rank 0: answers every request waiting; whether there was one.
    bool answer_requests() {
        bool any = false;
        int from = 0;
        while (transport::poll(transport::kDealRequest, from)) {
            std::uint32_t request[2];  // the asker's threads, items done since it last asked
            transport::receive(from, transport::kDealRequest, request, sizeof request);
            if (opt_.progress) opt_.progress->add(request[1]);
            const Chunk c = take(request[0]);
            const std::uint32_t reply[2] = {c.begin, c.end};
            transport::send(from, transport::kDealReply, reply, sizeof reply);
            if (c.begin == c.end) ++told_done_;
            any = true;
        }
        return any;
    }

    // How many items not started an asking rank keeps: two rounds of its threads, and about
    // kLeadSeconds of work at its pace so far (at most kLeadRounds rounds, lest a rank whose
    // first items were sky hoard fur). Rank 0 answers only between two of its own items: the
    // lead covers its items costing up to about kLeadSeconds per thread.
    std::uint64_t keep() const {
        const auto threads = static_cast<std::uint64_t>(threads_);
        const std::uint64_t done = done_.load(std::memory_order_relaxed);
        if (done < threads) return 2 * threads;
        const double per_item = seconds_since(t0_) / static_cast<double>(done);
        const auto lead = static_cast<std::uint64_t>(kLeadSeconds / per_item);
        return std::clamp(lead, 2 * threads, kLeadRounds * threads);
    }

    // Other ranks: takes the answer to the request sent, or sends one when down to keep()
    // items (one request at a time).
    void ask() {
        int from = 0;
        if (asked_ && transport::poll(transport::kDealReply, from)) {
            std::uint32_t reply[2];
            transport::receive(0, transport::kDealReply, reply, sizeof reply);
            asked_ = false;
            push({reply[0], reply[1]});
        }
        if (!asked_ && low(keep())) {
            const std::uint64_t done = done_.load();
            const std::uint32_t request[2] = {static_cast<std::uint32_t>(threads_),
                                              static_cast<std::uint32_t>(done - reported_)};
            reported_ = done;
            transport::send(0, transport::kDealRequest, request, sizeof request);
            asked_ = true;
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
