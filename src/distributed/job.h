#pragma once
// The job a `lattice` process belongs to: itself alone, or one rank of an MPI job when mpirun
// or srun started it (and the build found MPI). All of MPI lives in src/distributed; the rest of the
// code asks which rank it is and uses the collective steps below and in dist/deal.h, which are
// plain calls in a single process. "Collective" means every rank of the job makes the call,
// in the same order.
#include <cstdint>
#include <cstring>
#include <functional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "util/big_buffer.h"
#include "util/error.h"

namespace lat::dist {

// Joins the MPI job when the process was started into one and leaves it (after a barrier) at
// the end of its scope: one, at the top of main().
class Session {
public:
    Session(int& argc, char**& argv);
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;
};

int rank();
int ranks();
inline bool is_root() { return rank() == 0; }
inline bool distributed() { return ranks() > 1; }
// Whether this build can join MPI jobs at all.
bool built_with_mpi();

// Ends every rank of the job now with this exit code (MPI_Abort; mpirun then exits with it).
// For failures that not every rank reaches together; in a single process, std::exit.
[[noreturn]] void abort_job(int code);

// An input error agreed on by every rank (agree() below): every rank exits with 2 and the job
// ends in order, but only rank 0 prints the message, so the user reads it once.
class JobInputError : public InputError {
public:
    explicit JobInputError(const std::string& what) : InputError(what) {}
    bool print_here() const { return is_root(); }
};

// Collective: runs `step` here, then every rank learns whether it threw InputError anywhere.
// If so, every rank throws JobInputError with the message of the lowest failing rank (a rank
// other than 0 adds which rank and host it was). Other exceptions pass through untouched (the
// command line then ends the job with abort_job). In a single process: just step().
void agree(const std::function<void()>& step);
// agree() with a step that runs on rank 0 only (the others wait, sleeping).
void on_root(const std::function<void()>& step);
// on_root() for a step that can use more threads than a rank has: while the other ranks wait
// (asleep), rank 0 may use the threads of every rank on its node (their cores are idle), at
// most the cores it may run on. For rank 0's share of a table build (encoding every hit).
void on_root_with_node_threads(const std::function<void()>& step);
// Collective: throws JobInputError on every rank unless `fingerprint` is the same on every
// rank ("WHAT differs between rank 0 and rank N"): ranks rendering one image from different
// inputs (a node's stale copy of a scene) would otherwise make a wrong image without a word.
void agree_on(std::uint64_t fingerprint, const std::string& what);
// Collective: rank 0's answer, on every rank.
bool root_says(const std::function<bool()>& question);

void barrier();

// Collective: each rank's bytes, given in pieces, to rank 0. On rank 0 the result holds the
// other ranks' bytes (its own entry, [0], is empty); elsewhere it is empty. Any size: the
// pieces are streamed in 16 MB messages, without copying them whole.
std::vector<ByteBuffer> gather_to_root(std::span<const std::span<const std::uint8_t>> pieces);

// Collective: every rank's value, in rank order, on rank 0 (elsewhere: empty).
template <class T>
std::vector<T> gather_values(const T& mine) {
    static_assert(std::is_trivially_copyable_v<T>);
    const std::span<const std::uint8_t> piece(reinterpret_cast<const std::uint8_t*>(&mine), sizeof(T));
    std::vector<ByteBuffer> all = gather_to_root(std::span(&piece, 1));
    std::vector<T> out;
    if (!is_root()) return out;
    out.push_back(mine);
    for (std::size_t r = 1; r < all.size(); ++r) {
        T v;
        std::memcpy(&v, all[r].data(), sizeof(T));
        out.push_back(v);
    }
    return out;
}

// This machine's name, in a fixed-size value that gather_values can carry.
struct HostName {
    char text[64] = {};
    static HostName here();
};

}  // namespace lat::dist
