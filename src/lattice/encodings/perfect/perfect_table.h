#pragma once
// The paper's section 5.2.1 proposal, done literally: the set of pairs is known before the
// table is built, so a minimal perfect hash function (BBHash, lattice/bbhash.h) indexes the
// stored hits and the key (p_i, p_o) and the overflow pointer are omitted. Entry (5 bytes):
//   t      : 16 bits  the hit as p_i + t (p_o - p_i), t quantised to 1/65535 (as hash14)
//   normal : 24 bits  octahedral, 12 + 12 bits (angle error below 0.04 degrees)
// What that costs: a perfect hash cannot tell a stored pair from a missing one, so a pair that
// should miss gets some other pair's hit unless it falls through every level of the MPHF.
// The variants perfect6 and perfect7 add an 8- or 16-bit fingerprint of the key per entry,
// which turns all but 2^-8 or 2^-16 of those false hits back into misses.
// Payload: u64 hits, u32 fingerprint bits, u32 zero, u64 MPHF bytes, the MPHF, the entries.
#include <cstdint>
#include <optional>
#include <string>

#include "lattice/bits/bbhash.h"
#include "lattice/table.h"
#include "util/big_buffer.h"

namespace lat {

class PerfectTable final : public LatticeTable {
public:
    static constexpr std::uint32_t kMaxPoints = 0xFFFFFFFFu;
    static constexpr int kNormalBits = 12;

    // The key the MPHF sees for a pair.
    static std::uint64_t key(std::uint32_t a, std::uint32_t b) {
        return (static_cast<std::uint64_t>(a) << 32) | b;
    }
    // "perfect5", "perfect6", "perfect7" for 0, 8, 16 fingerprint bits.
    static std::string name(int fingerprint_bits);
    static int entry_bytes(int fingerprint_bits) { return 5 + fingerprint_bits / 8; }

    // From rasterized hits (distinct pairs). Parallel; the payload does not depend on the
    // thread count.
    static ByteBuffer build(const RawHits& hits, int fingerprint_bits);
    // Over a payload made by build with the same fingerprint bits (owned or memory-mapped,
    // 8-byte aligned; it must outlive the table). Throws std::runtime_error if inconsistent.
    PerfectTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                 int fingerprint_bits);

    bool lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const override;
    std::string encoding() const override { return name(fp_bits_); }
    std::uint64_t entries() const override { return mphf_->keys(); }
    std::uint64_t bytes() const override { return size_; }

    const BBHash& mphf() const { return *mphf_; }

private:
    std::optional<BBHash> mphf_;
    const std::uint8_t* e_ = nullptr;
    int fp_bits_ = 0, stride_ = 5;
    std::size_t size_ = 0;
};

}  // namespace lat
