#pragma once
// The images `lattice table2` writes besides each mode's own: the strip of whole images and the
// strip of magnified crops of one region, so that the modes can be told apart at a glance.
#include <vector>

#include "io/image.h"

namespace lat::cli {

// Images side by side, 4 background-grey pixels apart, in the order given.
Image8 image_strip(const std::vector<const Image8*>& images);

struct CropRegion {
    int x = 0, y = 0, size = 96;  // the square's top-left pixel and side
};

// The size x size square (on a grid of size / 4) where `reference` has the most detail: the
// largest sum of its pixels' gradient magnitudes. The whole image when it is smaller.
CropRegion busiest_region(const Image8& reference, int size);

// The region of each image, magnified `scale` times by pixel replication (no filtering, so
// every pixel is seen as rendered), as one strip.
Image8 crop_strip(const std::vector<const Image8*>& images, const CropRegion& region, int scale);

}  // namespace lat::cli
