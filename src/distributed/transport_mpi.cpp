// MPI (the build found it): compiled instead of transport_local.cpp. One thread at a time calls
// MPI (MPI_THREAD_SERIALIZED): the main thread, or in a dealt loop the worker that holds the
// dealer's message lock.
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>

#include "distributed/transport.h"

namespace lat::dist::transport {
namespace {

bool joined = false;
int my_rank = 0, world_size = 1;

// Process managers that start MPI ranks say so in the environment: Open MPI's mpirun, PMIx
// (srun --mpi=pmix, Open MPI 5, prterun) and PMI-1/2 (srun --mpi=pmi2, MPICH's hydra).
bool launched_by_process_manager() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
        if (const char* s = std::getenv(v); s && *s) return true;
    return false;
}

// Messages are split into pieces that fit MPI's int counts.
constexpr std::size_t kPiece = std::size_t{1} << 30;

void wait(MPI_Request& request) {
    for (int idle = 0;; ++idle) {
        int done = 0;
        MPI_Test(&request, &done, MPI_STATUS_IGNORE);
        if (done) return;
        idle_wait(idle);
    }
}

// A transfer of `bytes` as messages of at most kPiece bytes (one, if empty): start(offset,
// count, request) begins each, which is then waited for.
template <class Start>
void in_pieces(std::size_t bytes, Start&& start) {
    std::size_t at = 0;
    do {
        MPI_Request r;
        start(at, static_cast<int>(std::min(kPiece, bytes - at)), &r);
        wait(r);
        at += kPiece;
    } while (at < bytes);
}

}  // namespace

bool start(int& argc, char**& argv) {
    if (!launched_by_process_manager()) return false;
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
    joined = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &my_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &world_size);
    if (provided < MPI_THREAD_SERIALIZED) {
        if (my_rank == 0)
            std::fputs("lattice: error: the MPI library does not let threads call it one at a "
                       "time (MPI_THREAD_SERIALIZED), which the dealt loops need\n", stderr);
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    return true;
}

void stop() {
    if (!joined) return;
    barrier();  // sleeping here, not in MPI_Finalize's busy fence
    MPI_Finalize();
    joined = false;
}

int rank() { return my_rank; }
int size() { return world_size; }

std::string host() {
    char name[256] = {};
    ::gethostname(name, sizeof name - 1);
    return name;
}

void abort(int code) {
    if (joined) MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
}

void barrier() {
    if (!joined) return;
    MPI_Request r;
    MPI_Ibarrier(MPI_COMM_WORLD, &r);
    wait(r);
}

void allgather(const void* mine, std::size_t bytes, void* all) {
    MPI_Request r;
    MPI_Iallgather(mine, static_cast<int>(bytes), MPI_BYTE, all, static_cast<int>(bytes), MPI_BYTE,
                   MPI_COMM_WORLD, &r);
    wait(r);
}

void broadcast(void* data, std::size_t bytes) {
    in_pieces(bytes, [&](std::size_t at, int count, MPI_Request* r) {
        MPI_Ibcast(static_cast<std::uint8_t*>(data) + at, count, MPI_BYTE, 0, MPI_COMM_WORLD, r);
    });
}

void send(int to, int tag, const void* data, std::size_t bytes) {
    in_pieces(bytes, [&](std::size_t at, int count, MPI_Request* r) {
        MPI_Isend(static_cast<const std::uint8_t*>(data) + at, count, MPI_BYTE, to, tag, MPI_COMM_WORLD, r);
    });
}

void receive(int from, int tag, void* data, std::size_t bytes) {
    in_pieces(bytes, [&](std::size_t at, int count, MPI_Request* r) {
        MPI_Irecv(static_cast<std::uint8_t*>(data) + at, count, MPI_BYTE, from, tag, MPI_COMM_WORLD, r);
    });
}

bool poll(int tag, int& from) {
    int flag = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, tag, MPI_COMM_WORLD, &flag, &status);
    if (flag) from = status.MPI_SOURCE;
    return flag != 0;
}

void idle_wait(int idle) {
    if (const long ns = idle_pause_ns(idle); ns > 0) {
        const timespec ts{0, ns};
        nanosleep(&ts, nullptr);
    }
}

}  // namespace lat::dist::transport
