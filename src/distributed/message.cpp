#include "distributed/message.h"

namespace lat::dist {

std::span<const std::uint8_t> MessageReader::take(std::uint64_t count, std::size_t size) {
    const std::size_t left = bytes_.size() - at_;
    if (size != 0 && count > left / size)
        fail("it ends " + std::to_string(left) + " bytes after byte " + std::to_string(at_) + ", before the " +
             std::to_string(count) + " x " + std::to_string(size) + " bytes it announces");
    const std::span<const std::uint8_t> b = bytes_.subspan(at_, count * size);
    at_ += b.size();
    return b;
}

void MessageReader::expect_end() const {
    if (at_ != bytes_.size())
        fail(std::to_string(bytes_.size() - at_) + " bytes are left over after byte " + std::to_string(at_));
}

void MessageReader::fail(const std::string& why) const {
    throw MessageError("malformed " + what_ + " from rank " + std::to_string(from_) + " (" +
                       std::to_string(bytes_.size()) + " bytes): " + why);
}

void mark_dealt(std::span<const Chunk> chunks, std::vector<bool>& dealt, const MessageReader& reader) {
    for (const Chunk& c : chunks) {
        if (c.begin > c.end || c.end > dealt.size())
            reader.fail("items [" + std::to_string(c.begin) + ", " + std::to_string(c.end) +
                        ") are not a range of the loop's " + std::to_string(dealt.size()));
        for (std::uint32_t i = c.begin; i != c.end; ++i) {
            if (dealt[i]) reader.fail("item " + std::to_string(i) + " was dealt twice");
            dealt[i] = true;
        }
    }
}

}  // namespace lat::dist
