#include "util/big_buffer.h"

#include <sys/mman.h>

#include <cstdint>
#include <new>

namespace lat {

ByteBuffer::ByteBuffer(std::size_t size) : ByteBuffer(size, Pages::kHuge) {}

ByteBuffer::ByteBuffer(std::size_t size, Pages pages) : size_(size) {
    if (size == 0) return;
    constexpr std::size_t kHuge = std::size_t{2} << 20;
    if (size > SIZE_MAX - 2 * kHuge) throw std::bad_alloc();  // the roundings below would wrap
    mapped_ = (size + kHuge - 1) / kHuge * kHuge;
    // Huge pages need 2 MB-aligned ranges: map 2 MB more, keep the aligned middle (recent
    // kernels align large anonymous mappings themselves; older ones do not).
    void* p = ::mmap(nullptr, mapped_ + kHuge, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    const auto start = reinterpret_cast<std::uintptr_t>(p);
    const std::uintptr_t aligned = (start + kHuge - 1) / kHuge * kHuge;
    if (aligned > start) ::munmap(p, aligned - start);
    if (const std::uintptr_t end = start + mapped_ + kHuge; end > aligned + mapped_)
        ::munmap(reinterpret_cast<void*>(aligned + mapped_), end - aligned - mapped_);
    data_ = reinterpret_cast<std::uint8_t*>(aligned);
    if (pages == Pages::kHuge) ::madvise(data_, mapped_, MADV_HUGEPAGE);  // a hint; fine if refused
}

void ByteBuffer::shrink(std::size_t size) {
    if (size >= size_) return;
    constexpr std::size_t kHuge = std::size_t{2} << 20;
    const std::size_t keep = (size + kHuge - 1) / kHuge * kHuge;
    if (keep < mapped_) {
        ::munmap(data_ + keep, mapped_ - keep);
        mapped_ = keep;
    }
    size_ = size;
    if (mapped_ == 0) data_ = nullptr;
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
