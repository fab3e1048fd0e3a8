#pragma once
// Large uninitialised buffers (tables, messages between ranks): anonymous memory with
// transparent huge pages requested, so that filling hundreds of megabytes does not spend its
// time in 4 kB page faults (first touches are slow on virtual machines: about 10 ms per 2 MB of
// 4 kB pages on ours), and nothing is written twice (the kernel's zeroing aside).
#include <cstddef>
#include <cstdint>

namespace lat {

class ByteBuffer {
public:
    ByteBuffer() = default;
    explicit ByteBuffer(std::size_t size);
    // Pages as the system gives them, 4 kB where it does not make them huge by itself: for a
    // buffer filled bit by bit across its whole range while others are freed (the pages of a
    // huge-page buffer are all first touched at once, before anything is freed).
    enum class Pages { kHuge, kSmall };
    ByteBuffer(std::size_t size, Pages pages);
    ~ByteBuffer();
    ByteBuffer(ByteBuffer&& o) noexcept : data_(o.data_), size_(o.size_), mapped_(o.mapped_) {
        o.data_ = nullptr, o.size_ = 0, o.mapped_ = 0;
    }
    ByteBuffer& operator=(ByteBuffer&& o) noexcept;
    ByteBuffer(const ByteBuffer&) = delete;
    ByteBuffer& operator=(const ByteBuffer&) = delete;

    std::uint8_t* data() { return data_; }
    const std::uint8_t* data() const { return data_; }
    std::size_t size() const { return size_; }
    // Keeps the first `size` bytes (at most size()) and gives the whole huge pages beyond back
    // to the system, so that the memory a later buffer touches first can be these pages.
    void shrink(std::size_t size);

private:
    std::uint8_t* data_ = nullptr;
    std::size_t size_ = 0;
    std::size_t mapped_ = 0;
};

}  // namespace lat
