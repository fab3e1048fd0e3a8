#include "table2_images.h"

#include <algorithm>
#include <cassert>
#include <cstdlib>

namespace lat::cli {

Image8 image_strip(const std::vector<const Image8*>& images) {
    constexpr int kGap = 4;
    int w = 0, h = 0;
    for (const Image8* im : images) {
        w += im->width + (w ? kGap : 0);
        h = std::max(h, im->height);
    }
    Image8 out{w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(w) * h * 3, 128)};
    int x0 = 0;
    for (const Image8* im : images) {
        for (int y = 0; y < im->height; ++y)
            std::copy_n(im->rgb.begin() + static_cast<std::ptrdiff_t>(y) * im->width * 3,
                        im->width * 3,
                        out.rgb.begin() + (static_cast<std::ptrdiff_t>(y) * w + x0) * 3);
        x0 += im->width + kGap;
    }
    return out;
}

CropRegion busiest_region(const Image8& im, int size) {
    const int w = im.width, h = im.height;
    CropRegion best{0, 0, std::min({size, w, h})};
    if (best.size < 1) return best;
    // Gradient magnitude per pixel (sum over channels of |right - here| + |below - here|),
    // then a summed-area table to score every window.
    std::vector<long long> sat(static_cast<std::size_t>(w + 1) * (h + 1), 0);
    auto at = [&](int x, int y, int c) {
        return int{im.rgb[(static_cast<std::size_t>(y) * w + x) * 3 + c]};
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            long long g = 0;
            for (int c = 0; c < 3; ++c) {
                if (x + 1 < w) g += std::abs(at(x + 1, y, c) - at(x, y, c));
                if (y + 1 < h) g += std::abs(at(x, y + 1, c) - at(x, y, c));
            }
            const auto i = [&](int xx, int yy) {
                return static_cast<std::size_t>(yy) * (w + 1) + xx;
            };
            sat[i(x + 1, y + 1)] = g + sat[i(x, y + 1)] + sat[i(x + 1, y)] - sat[i(x, y)];
        }
    const int s = best.size, step = std::max(1, s / 4);
    long long top = -1;
    for (int y = 0; y + s <= h; y += step)
        for (int x = 0; x + s <= w; x += step) {
            const auto i = [&](int xx, int yy) {
                return static_cast<std::size_t>(yy) * (w + 1) + xx;
            };
            const long long sum =
                sat[i(x + s, y + s)] - sat[i(x, y + s)] - sat[i(x + s, y)] + sat[i(x, y)];
            if (sum > top) {
                top = sum;
                best.x = x;
                best.y = y;
            }
        }
    return best;
}

Image8 crop_strip(const std::vector<const Image8*>& images, const CropRegion& r, int scale) {
    std::vector<Image8> crops;
    crops.reserve(images.size());
    const int side = r.size * scale;
    for (const Image8* im : images) {
        assert(r.x >= 0 && r.y >= 0 && r.x + r.size <= im->width && r.y + r.size <= im->height);
        Image8 c{side, side, std::vector<std::uint8_t>(static_cast<std::size_t>(side) * side * 3)};
        for (int y = 0; y < side; ++y)
            for (int x = 0; x < side; ++x) {
                const std::ptrdiff_t from =
                    static_cast<std::ptrdiff_t>(r.y + y / scale) * im->width + r.x + x / scale;
                std::copy_n(im->rgb.begin() + from * 3, 3,
                            c.rgb.begin() + (static_cast<std::ptrdiff_t>(y) * side + x) * 3);
            }
        crops.push_back(std::move(c));
    }
    std::vector<const Image8*> ptrs;
    for (const Image8& c : crops) ptrs.push_back(&c);
    return image_strip(ptrs);
}

}  // namespace lat::cli
