// lattice.to_srgb8 and lattice.compare, and the arrays renders return.
#include <pybind11/stl.h>

#include "bindings.h"
#include "io/image_compare.h"
#include "util/error.h"
#include "util/hash.h"

namespace lat::py {
namespace {

constexpr const char* kHolderName = "lattice.RenderedImage";

std::uint64_t hash_of(const float* data, std::size_t n) { return hash_bytes(data, n * sizeof(float)); }

// The render's own holder behind arr, if arr is a render's array, whole and unmodified.
const RenderedImage* holder_of(const pyb::array& arr) {
    const pyb::handle base = arr.base();
    if (!base || !pyb::isinstance<pyb::capsule>(base)) return nullptr;
    const auto cap = pyb::reinterpret_borrow<pyb::capsule>(base);
    if (cap.name() == nullptr || std::string(cap.name()) != kHolderName) return nullptr;
    const auto* h = cap.get_pointer<RenderedImage>();
    const std::size_t n = h->radiance.rgb.size();
    if (arr.data() != h->radiance.rgb.data() || arr.ndim() != 3 || arr.shape(0) != h->radiance.height ||
        arr.shape(1) != h->radiance.width || arr.shape(2) != 3 || !(arr.flags() & pyb::array::c_style) ||
        hash_of(h->radiance.rgb.data(), n) != h->radiance_hash)
        return nullptr;
    return h;
}

std::pair<int, int> image_shape(const pyb::array& a, const char* what) {
    if (a.ndim() != 3 || a.shape(2) != 3)
        throw InputError(std::string(what) + ": expected an H x W x 3 array, not one of shape " +
                         pyb::str(a.attr("shape")).cast<std::string>());
    return {static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1))};
}

// round(255 clamp(c, 0, 1)) per channel, the command line's 8-bit rule (no gamma).
Image8 bytes_of(const pyb::array& any, const char* what) {
    const auto [h, w] = image_shape(any, what);
    if (pyb::isinstance<pyb::array_t<std::uint8_t>>(any)) {
        const auto a = pyb::array_t<std::uint8_t, pyb::array::c_style | pyb::array::forcecast>::ensure(any);
        return Image8{w, h, std::vector<std::uint8_t>(a.data(), a.data() + a.size())};
    }
    const auto a = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(any);
    if (!a) throw InputError(std::string(what) + ": expected an array of numbers");
    Image8 out{w, h, std::vector<std::uint8_t>(static_cast<std::size_t>(a.size()))};
    const double* v = a.data();
    for (std::size_t i = 0; i < out.rgb.size(); ++i) out.rgb[i] = to_byte(v[i]);
    return out;
}

pyb::array_t<std::uint8_t> to_srgb8(const pyb::array& img) {
    if (const RenderedImage* h = holder_of(img)) return image8_array(h->display);
    return image8_array(bytes_of(img, "img"));
}

pyb::dict compare(const pyb::array& a, const pyb::array& b, int threshold) {
    const Image8 ia = holder_of(a) ? holder_of(a)->display : bytes_of(a, "a");
    const Image8 ib = holder_of(b) ? holder_of(b)->display : bytes_of(b, "b");
    require_same_size(ia, "a", ib, "b");
    const ImageDiffStats s = compare_images(ia, ib, threshold);
    pyb::dict d;
    d["psnr_db"] = s.psnr_db;
    d["ssim"] = s.ssim;
    d["share_over_8"] = s.share_over_8;
    d["pixels_over_8"] = s.pixels_over_8;
    d["rmse"] = s.rmse;
    d["mean_abs_error"] = s.mean_abs_error;
    d["max_abs_error"] = s.max_abs_error;
    d["threshold"] = s.threshold;
    return d;
}

}  // namespace

pyb::array_t<float> radiance_array(RenderOutput&& out) {
    auto* h = new RenderedImage{std::move(out.radiance), std::move(out.display), 0};
    h->radiance_hash = hash_of(h->radiance.rgb.data(), h->radiance.rgb.size());
    const pyb::capsule owner(h, kHolderName, [](PyObject* cap) {
        delete static_cast<RenderedImage*>(PyCapsule_GetPointer(cap, kHolderName));
    });
    const pyb::ssize_t height = h->radiance.height, width = h->radiance.width;
    return pyb::array_t<float>({height, width, pyb::ssize_t{3}}, h->radiance.rgb.data(), owner);
}

pyb::array_t<std::uint8_t> image8_array(const Image8& img) {
    pyb::array_t<std::uint8_t> a({pyb::ssize_t{img.height}, pyb::ssize_t{img.width}, pyb::ssize_t{3}});
    std::copy(img.rgb.begin(), img.rgb.end(), a.mutable_data());
    return a;
}

void bind_images(pyb::module_& m) {
    m.def("read_png", [](const std::string& path) { return image8_array(read_png(path)); }, pyb::arg("path"),
          "A PNG file as an H x W x 3 uint8 array (as `lattice compare` reads it)");
    m.def("to_srgb8", &to_srgb8, pyb::arg("img"), R"(8-bit RGB as the command line's PNG holds it.

round(255 * clamp(c, 0, 1)) per channel, with no gamma curve (the paper's rule). For an array
render() returned, unmodified, these are exactly the PNG's pixels: with spp > 1 the PNG
averages clamped samples, which the radiance alone cannot give.)");
    m.def("compare", &compare, pyb::arg("a"), pyb::arg("b"), pyb::arg("threshold") = 8,
          R"(Compares two images as `lattice compare` does.

Float images are first made 8-bit by to_srgb8. Returns a dict: psnr_db (inf if identical),
ssim (nan under 11 x 11 pixels), share_over_8 (the share of pixels with a channel off by more
than threshold/255), pixels_over_8, rmse, mean_abs_error, max_abs_error, threshold.)");
}

}  // namespace lat::py
