#include "render/core/rank_stats.h"

#include <cstring>

#include "distributed/job.h"
#include "distributed/message.h"
#include "util/memory.h"

namespace lat {
namespace {

// Calls row(first, count) for each row of the chunks' tiles, in order: the index of its first
// pixel in the image and its length in pixels.
template <class F>
void for_each_tile_row(const TileGrid& g, std::span<const dist::Chunk> chunks, F&& row) {
    const auto tiles_x = static_cast<std::uint32_t>(g.tiles_x());
    for (const dist::Chunk& c : chunks)
        for (std::uint32_t tile = c.begin; tile != c.end; ++tile) {
            const int x0 = static_cast<int>(tile % tiles_x) * g.tile;
            const int y0 = static_cast<int>(tile / tiles_x) * g.tile;
            const auto count = static_cast<std::size_t>(std::min(g.width, x0 + g.tile) - x0);
            for (int j = y0; j < std::min(g.height, y0 + g.tile); ++j)
                row(static_cast<std::size_t>(j) * static_cast<std::size_t>(g.width) +
                        static_cast<std::size_t>(x0),
                    count);
        }
}

}  // namespace

// The chunk list, then the radiance and the display rows of those tiles, in that order (15
// bytes a pixel).
void gather_tiles(const TileGrid& grid, const dist::DealReport& mine, std::span<float> radiance,
                  std::span<std::uint8_t> display) {
    const std::uint64_t nchunks = mine.chunks.size();
    std::vector<std::span<const std::uint8_t>> pieces{
        {reinterpret_cast<const std::uint8_t*>(&nchunks), sizeof nchunks},
        {reinterpret_cast<const std::uint8_t*>(mine.chunks.data()), nchunks * sizeof(dist::Chunk)}};
    for_each_tile_row(grid, mine.chunks, [&](std::size_t first, std::size_t count) {
        pieces.emplace_back(reinterpret_cast<const std::uint8_t*>(radiance.data() + first * 3),
                            count * 3 * sizeof(float));
    });
    for_each_tile_row(grid, mine.chunks, [&](std::size_t first, std::size_t count) {
        pieces.emplace_back(display.data() + first * 3, count * 3);
    });
    const std::vector<ByteBuffer> all = dist::gather_to_root(pieces);
    if (!dist::is_root()) return;
    // What the other ranks sent is checked before it is copied: every tile of the image from
    // exactly one rank, and rows that fill the message exactly.
    std::vector<bool> dealt(static_cast<std::size_t>(grid.tiles_x()) *
                            static_cast<std::size_t>(grid.tiles_y()));
    dist::mark_dealt(mine.chunks, dealt, dist::MessageReader({}, "tile list", 0));
    for (std::size_t r = 1; r < all.size(); ++r) {
        dist::MessageReader in({all[r].data(), all[r].size()}, "tiles message",
                               static_cast<int>(r));
        const std::span<const std::uint8_t> list =
            in.take(in.read<std::uint64_t>(), sizeof(dist::Chunk));
        std::vector<dist::Chunk> chunks(list.size() / sizeof(dist::Chunk));
        if (!list.empty()) std::memcpy(chunks.data(), list.data(), list.size());
        dist::mark_dealt(chunks, dealt, in);
        for_each_tile_row(grid, chunks, [&](std::size_t first, std::size_t count) {
            in.read(radiance.data() + first * 3, count * 3);
        });
        for_each_tile_row(grid, chunks, [&](std::size_t first, std::size_t count) {
            in.read(display.data() + first * 3, count * 3);
        });
        in.expect_end();
    }
    for (std::size_t t = 0; t < dealt.size(); ++t)
        if (!dealt[t]) throw dist::MessageError("tile " + std::to_string(t) + " came from no rank");
}

std::vector<RankStats> gather_rank_stats(const dist::DealReport& deal, RankStats mine) {
    mine.rank = dist::rank();
    const dist::HostName host = dist::HostName::here();
    std::memcpy(mine.host, host.text, sizeof mine.host);
    mine.threads = deal.threads;
    mine.tiles = static_cast<std::uint32_t>(deal.items);
    mine.chunks = static_cast<std::uint32_t>(deal.chunks.size());
    mine.render_ms = deal.seconds * 1e3;
    mine.wait_ms = deal.wait_seconds * 1e3;
    mine.peak_memory_bytes = peak_rss_bytes();
    mine.timeline = dist::timeline();
    return dist::gather_values(mine);
}

}  // namespace lat
