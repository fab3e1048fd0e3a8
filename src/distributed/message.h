#pragma once
// Reading what another rank sent (gathered tiles, rasterized blocks) without trusting it: a
// message that is too short, too long or names items outside the loop (a bug, or ranks that
// run different builds) throws MessageError, never reads or writes out of bounds.
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "distributed/deal.h"

namespace lat::dist {

// An internal error (exit code 1; in an MPI job it ends every rank).
class MessageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

class MessageReader {
public:
    // `what` and `from` name the message in errors.
    MessageReader(std::span<const std::uint8_t> bytes, std::string what, int from)
        : bytes_(bytes), what_(std::move(what)), from_(from) {}

    // The next count values of T, copied out.
    template <class T>
    void read(T* out, std::size_t count) {
        static_assert(std::is_trivially_copyable_v<T>);
        const std::span<const std::uint8_t> b = take(count, sizeof(T));
        if (!b.empty()) std::memcpy(out, b.data(), b.size());
    }
    template <class T>
    T read() {
        T v;
        read(&v, 1);
        return v;
    }
    // The next count values of T, where they lie in the message (count * size bytes).
    std::span<const std::uint8_t> take(std::uint64_t count, std::size_t size);
    // Throws unless every byte was read.
    void expect_end() const;
    [[noreturn]] void fail(const std::string& why) const;

private:
    std::span<const std::uint8_t> bytes_;
    std::size_t at_ = 0;
    std::string what_;
    int from_;
};

// Marks the items of `chunks` in `dealt` (one flag per item of the loop): throws MessageError
// (through `reader`) for a chunk that is reversed, reaches past the loop or holds an item
// already marked (dealt twice).
void mark_dealt(std::span<const Chunk> chunks, std::vector<bool>& dealt, const MessageReader& reader);

}  // namespace lat::dist
