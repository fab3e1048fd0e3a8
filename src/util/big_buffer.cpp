#include "util/big_buffer.h"

#include <sys/mman.h>

#include <new>

namespace lat {

ByteBuffer::ByteBuffer(std::size_t size) : size_(size) {
    if (size == 0) return;
    constexpr std::size_t kHuge = std::size_t{2} << 20;
    mapped_ = (size + kHuge - 1) / kHuge * kHuge;
    void* p = ::mmap(nullptr, mapped_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    ::madvise(p, mapped_, MADV_HUGEPAGE);  // a hint; fine if refused
    data_ = static_cast<std::uint8_t*>(p);
}

ByteBuffer::~ByteBuffer() {
    if (data_) ::munmap(data_, mapped_);
}

ByteBuffer& ByteBuffer::operator=(ByteBuffer&& o) noexcept {
    if (this != &o) {
        if (data_) ::munmap(data_, mapped_);
        data_ = o.data_, size_ = o.size_, mapped_ = o.mapped_;
        o.data_ = nullptr, o.size_ = 0, o.mapped_ = 0;
    }
    return *this;
}

}  // namespace lat
