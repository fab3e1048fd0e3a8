#include "distributed/job.h"

#include <algorithm>
#include <cstring>

#include "distributed/timeline.h"
#include "distributed/transport.h"
#include "util/hash.h"
#include "util/threads.h"

namespace lat::dist {

Session::Session(int& argc, char**& argv) {
    transport::start(argc, argv);
    mark(Step::kJoined);
}
Session::~Session() { transport::stop(); }

int rank() { return transport::rank(); }
int ranks() { return transport::size(); }

bool built_with_mpi() {
#ifdef LATTICE_WITH_MPI
    return true;
#else
    return false;
#endif
}

void abort_job(int code) { transport::abort(code); }

void barrier() { transport::barrier(); }

HostName HostName::here() {
    HostName h;
    const std::string name = transport::host();
    std::memcpy(h.text, name.data(), std::min(name.size(), sizeof h.text - 1));
    return h;
}

void agree(const std::function<void()>& step) {
    if (!distributed()) return step();
    std::string message;
    std::uint8_t failed = 0;
    try {
        step();
    } catch (const InputError& e) {
        message = e.what();
        failed = 1;
    }
    std::vector<std::uint8_t> all(static_cast<std::size_t>(ranks()));
    transport::allgather(&failed, 1, all.data());
    const auto first = std::find(all.begin(), all.end(), 1);
    if (first == all.end()) return;
    const int f = static_cast<int>(first - all.begin());
    if (f != 0 && rank() == f) {
        message += " (on rank " + std::to_string(f) + " of " + std::to_string(ranks()) + ", host " +
                   transport::host() + ")";
        const std::uint64_t n = message.size();
        transport::send(0, transport::kAgree, &n, sizeof n);
        transport::send(0, transport::kAgree, message.data(), n);
    } else if (f != 0 && is_root()) {
        std::uint64_t n = 0;
        transport::receive(f, transport::kAgree, &n, sizeof n);
        message.assign(n, '\0');
        transport::receive(f, transport::kAgree, message.data(), n);
    }
    throw JobInputError(message);
}

void agree_on(std::uint64_t fingerprint, const std::string& what) {
    if (!distributed()) return;
    std::vector<std::uint64_t> all(static_cast<std::size_t>(ranks()));
    transport::allgather(&fingerprint, sizeof fingerprint, all.data());
    for (std::size_t r = 1; r < all.size(); ++r)
        if (all[r] != all[0])
            throw JobInputError(what + " differs between rank 0 and rank " + std::to_string(r) +
                                " (every rank must run the same command on the same files)");
}

void on_root(const std::function<void()>& step) {
    agree([&] {
        if (is_root()) step();
    });
}

void on_root_with_node_threads(const std::function<void()>& step) {
    if (!distributed()) return step();
    // Each rank's host (hashed) and thread count.
    struct Rank {
        std::uint64_t host;
        std::int64_t threads;
    };
    const std::string host = transport::host();
    const Rank mine{hash_bytes(host.data(), host.size()), thread_count()};
    std::vector<Rank> all(static_cast<std::size_t>(ranks()));
    transport::allgather(&mine, sizeof mine, all.data());
    std::int64_t node_threads = 0;
    for (const Rank& r : all)
        if (r.host == all[0].host) node_threads += r.threads;
    on_root([&] {
        const WiderThreads wider(static_cast<int>(std::min<std::int64_t>(
            node_threads, core_count())));
        step();
    });
}

bool root_says(const std::function<bool()>& question) {
    std::uint8_t answer = is_root() && question() ? 1 : 0;
    transport::broadcast(&answer, 1);
    return answer != 0;
}

std::vector<ByteBuffer> gather_to_root(std::span<const std::span<const std::uint8_t>> pieces) {
    constexpr std::size_t kChunk = std::size_t{16} << 20;
    std::vector<ByteBuffer> out;
    if (is_root()) {
        out.resize(static_cast<std::size_t>(ranks()));
        for (int r = 1; r < ranks(); ++r) {
            std::uint64_t size = 0;
            transport::receive(r, transport::kGather, &size, sizeof size);
            ByteBuffer& b = out[static_cast<std::size_t>(r)];
            b = ByteBuffer(size);
            for (std::size_t at = 0; at < size; at += kChunk)
                transport::receive(r, transport::kGather, b.data() + at, std::min(kChunk, size - at));
        }
        return out;
    }
    std::uint64_t total = 0;
    for (const auto& p : pieces) total += p.size();
    transport::send(0, transport::kGather, &total, sizeof total);
    // The pieces, copied through one staging buffer into messages of exactly kChunk bytes
    // (the last one shorter), as rank 0 receives them. The buffer asks for huge pages: faulting
    // in fresh 4 kB pages can cost more than the copy.
    ByteBuffer stage(std::min<std::uint64_t>(kChunk, total));
    std::size_t staged = 0;
    for (const auto& p : pieces) {
        for (std::size_t at = 0; at < p.size();) {
            const std::size_t n = std::min(stage.size() - staged, p.size() - at);
            std::memcpy(stage.data() + staged, p.data() + at, n);
            staged += n;
            at += n;
            if (staged == stage.size()) {
                transport::send(0, transport::kGather, stage.data(), staged);
                staged = 0;
            }
        }
    }
    if (staged > 0) transport::send(0, transport::kGather, stage.data(), staged);
    return out;
}

}  // namespace lat::dist
