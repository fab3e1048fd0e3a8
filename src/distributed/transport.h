#pragma once
// The few message-passing primitives src/distributed is built on: MPI when the build found it
// (transport_mpi.cpp), one process otherwise (transport_local.cpp). Internal to src/distributed; the
// rest of the code uses dist/job.h and dist/deal.h.
//
// Every wait polls with short sleeps instead of spinning the way blocking MPI calls do, so a
// rank that waits (for rank 0 encoding a table, for the dispatcher) leaves its core to the
// ranks still working on the node.
#include <cstddef>
#include <string>

namespace lat::dist::transport {

// Message tags, one per protocol, so that no two protocols can take each other's messages.
enum Tag : int { kDealRequest = 1, kDealReply, kGather, kAgree };

// Joins the MPI job when a process manager (mpirun, srun) started this process; a plain run
// never calls MPI_Init (as a singleton it costs close to a second). Returns whether it joined.
bool start(int& argc, char**& argv);
// Leaves the job (after a barrier); nothing when start() did not join one.
void stop();

int rank();
int size();
std::string host();
[[noreturn]] void abort(int code);

void barrier();
// Every rank's `bytes` bytes from `mine`, in rank order, into `all` (size() * bytes).
void allgather(const void* mine, std::size_t bytes, void* all);
// Rank 0's `bytes` bytes at `data` to every rank.
void broadcast(void* data, std::size_t bytes);

// Point to point, in messages of any size (split below 2^31 bytes inside).
void send(int to, int tag, const void* data, std::size_t bytes);
void receive(int from, int tag, void* data, std::size_t bytes);
// Whether a message with `tag` from any rank is waiting; `from` is then its sender.
bool poll(int tag, int& from);

// How long a waiting loop pauses after `idle` empty polls in a row: not at all for the first
// few (an answer on its way is not delayed), then 50 us doubling to 0.8 ms. Each poll costs a
// few microseconds of CPU, which a rank waiting while its threads render takes from them.
inline long idle_pause_ns(int idle) {
    if (idle < 4) return 0;
    return 50'000L << (idle - 4 < 4 ? idle - 4 : 4);
}
// Sleeps idle_pause_ns(idle).
void idle_wait(int idle);

}  // namespace lat::dist::transport
