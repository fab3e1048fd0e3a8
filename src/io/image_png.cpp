// PNG reading and writing with libpng's low-level API. The simplified png_image API would treat
// 16-bit files as linear and gamma-convert them, but we want the stored sample values.
//
// libpng reports errors by longjmp. The functions that call setjmp (encode, decode) keep no
// C++ objects with destructors in their frames and change no locals after setjmp, so the jump
// back skips nothing; everything they fill lives in their callers.
#include <png.h>
#include <sys/stat.h>

#include <cassert>
#include <cerrno>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "io/image.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/file.h"

namespace lat {

namespace {

// Largest PNG we read: 2^28 pixels (768 MB as 8-bit RGB), each side at most 2^20.
constexpr std::uint32_t kMaxPngSide = 1u << 20;
constexpr std::uint64_t kMaxPngPixels = std::uint64_t{1} << 28;
// Files beyond 4 GiB: even 2^28 16-bit RGBA pixels stored raw take 2 GiB.
constexpr std::uint64_t kMaxPngFileBytes = std::uint64_t{4} << 30;

// Shared by libpng's callbacks and us; a plain struct, since callbacks run between setjmp and
// longjmp.
struct PngContext {
    std::FILE* file = nullptr;
    int os_error = 0;        // errno of a failed read or write, if that caused the error
    bool truncated = false;  // the read hit end of file
    char message[200] = {};
};

PngContext* context(png_structp png) {
    return static_cast<PngContext*>(png_get_io_ptr(png));
}

[[noreturn]] void on_error(png_structp png, png_const_charp msg) {
    auto* ctx = static_cast<PngContext*>(png_get_error_ptr(png));
    std::snprintf(ctx->message, sizeof ctx->message, "%s", msg);
    png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // benign chunk oddities: not worth a message

void write_data(png_structp png, png_bytep data, png_size_t n) {
    PngContext* ctx = context(png);
    if (std::fwrite(data, 1, n, ctx->file) != n) {
        ctx->os_error = errno != 0 ? errno : EIO;
        png_error(png, "write failed");
    }
}

void flush_data(png_structp png) {
    PngContext* ctx = context(png);
    if (std::fflush(ctx->file) != 0) {
        ctx->os_error = errno != 0 ? errno : EIO;
        png_error(png, "write failed");
    }
}

void read_data(png_structp png, png_bytep data, png_size_t n) {
    PngContext* ctx = context(png);
    if (std::fread(data, 1, n, ctx->file) != n) {
        if (std::ferror(ctx->file)) {
            ctx->os_error = errno != 0 ? errno : EIO;
            png_error(png, "read failed");
        }
        ctx->truncated = true;
        png_error(png, "file is truncated");
    }
}

bool encode(png_structp png, png_infop info, const Image8& img, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_IHDR(png, info, static_cast<png_uint_32>(img.width),
                 static_cast<png_uint_32>(img.height), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, nullptr);
    return true;
}

// Reads the header and sets the transforms down to 8-bit RGB; returns false on a libpng error.
// stored_bits: bits per pixel as stored (before the transforms), for the size check.
bool decode_header(png_structp png, png_infop info, int& stored_bits) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_sig_bytes(png, 8);
    png_read_info(png, info);
    const int type = png_get_color_type(png, info);
    const int depth = png_get_bit_depth(png, info);
    stored_bits = depth * png_get_channels(png, info);
    if (type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (type == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (depth == 16) png_set_scale_16(png);
    // Palette expansion turns tRNS into an alpha channel, so strip after it as well.
    if ((type & PNG_COLOR_MASK_ALPHA) != 0 || png_get_valid(png, info, PNG_INFO_tRNS) != 0) {
        png_set_strip_alpha(png);
    }
    if ((type & PNG_COLOR_MASK_COLOR) == 0) png_set_gray_to_rgb(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    return true;
}

bool decode_pixels(png_structp png, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_read_image(png, rows);
    png_read_end(png, nullptr);  // checks the rest of the file, so truncation is noticed
    return true;
}

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};

[[noreturn]] void throw_read_error(const std::string& path, const std::string& what) {
    throw InputError(located_message(path, "", what));
}

[[noreturn]] void throw_decode_error(const std::string& path, const PngContext& ctx) {
    if (ctx.os_error != 0)
        throw_read_error(path, "cannot read: " + std::string(std::strerror(ctx.os_error)));
    if (ctx.truncated) throw_read_error(path, "truncated PNG file");
    throw_read_error(path, "corrupt PNG file: " + std::string(ctx.message));
}

// Before allocating for the pixels, the header's claim must be plausible: within our limit and
// within what the file can hold. Deflate compresses at most 1032:1, so a file of n bytes holds
// at most about 1032 n bytes of pixel data; a 69-byte file cannot be 20000 x 20000.
void check_claimed_size(const std::string& path, std::FILE* file, int width, int height,
                        int stored_bits) {
    const std::uint64_t pixels =
        static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
    const std::string claim =
        "PNG header claims " + std::to_string(width) + " x " + std::to_string(height) + " pixels";
    if (pixels > kMaxPngPixels)
        throw_read_error(path, claim + ", over the limit of " + std::to_string(kMaxPngPixels));
    struct stat st {};
    if (::fstat(::fileno(file), &st) != 0 || !S_ISREG(st.st_mode)) return;  // a pipe: no bound
    const std::uint64_t pixel_bytes = (pixels * static_cast<std::uint64_t>(stored_bits) + 7) / 8;
    const auto file_bytes = static_cast<std::uint64_t>(st.st_size);
    if (pixel_bytes / 1032 > file_bytes)
        throw_read_error(path, claim + ", more than a " + std::to_string(file_bytes) +
                                   "-byte file can hold (truncated or corrupt PNG file)");
}

}  // namespace

void write_png(const std::string& path, const Image8& img) {
    require_nonempty_image(path, img.width, img.height);
    assert(img.rgb.size() == 3 * static_cast<std::size_t>(img.width) * img.height);
    AtomicFile out(path);
    PngContext ctx;
    ctx.file = out.file();
    std::vector<png_bytep> rows(static_cast<std::size_t>(img.height));
    for (int y = 0; y < img.height; ++y) {
        // libpng's API is not const-correct; it only reads the rows.
        rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(
            img.rgb.data() + 3 * static_cast<std::size_t>(img.width) * static_cast<std::size_t>(y));
    }
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &ctx, on_error, on_warning);
    png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
    bool ok = false;
    if (info != nullptr) {
        png_set_write_fn(png, &ctx, write_data, flush_data);
        ok = encode(png, info, img, rows.data());
    } else {
        std::snprintf(ctx.message, sizeof ctx.message, "out of memory");
    }
    png_destroy_write_struct(&png, &info);
    if (!ok) {
        if (ctx.os_error != 0) throw_write_errno(path, ctx.os_error);
        throw_write_error(path, ctx.message);
    }
    out.commit();
}

Image8 read_png(const std::string& path) {
    InputFile input(path, "PNG file", kMaxPngFileBytes);
    std::unique_ptr<std::FILE, FileCloser> file(::fdopen(input.fd(), "rb"));
    if (!file) throw_read_error(path, "cannot read: " + std::string(std::strerror(errno)));
    input.release();  // the FILE owns it now
    png_byte signature[8] = {};
    const std::size_t got = std::fread(signature, 1, sizeof signature, file.get());
    if (std::ferror(file.get())) {
        throw_read_error(path, "cannot read: " + std::string(std::strerror(errno)));
    }
    if (got == 0) throw_read_error(path, "empty file, not a PNG");
    if (png_sig_cmp(signature, 0, got) != 0) throw_read_error(path, "not a PNG file");
    if (got < sizeof signature) throw_read_error(path, "truncated PNG file");

    PngContext ctx;
    ctx.file = file.get();
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &ctx, on_error, on_warning);
    png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
    // Destroys the libpng state on every way out, including bad_alloc from the vectors below.
    struct Guard {
        png_structp& png;
        png_infop& info;
        ~Guard() { png_destroy_read_struct(&png, &info, nullptr); }
    } guard{png, info};
    if (info == nullptr) throw_read_error(path, "cannot read: out of memory");
    png_set_read_fn(png, &ctx, read_data);
    // libpng refuses larger headers itself (with "Image width/height exceeds user limit").
    png_set_user_limits(png, kMaxPngSide, kMaxPngSide);
    int stored_bits = 0;
    if (!decode_header(png, info, stored_bits)) throw_decode_error(path, ctx);

    Image8 img;
    img.width = static_cast<int>(png_get_image_width(png, info));
    img.height = static_cast<int>(png_get_image_height(png, info));
    check_claimed_size(path, file.get(), img.width, img.height, stored_bits);
    const std::size_t row_bytes = 3 * static_cast<std::size_t>(img.width);
    if (png_get_rowbytes(png, info) != row_bytes) {
        throw_read_error(path, "unsupported PNG layout");  // the transforms above rule this out
    }
    img.rgb.resize(row_bytes * static_cast<std::size_t>(img.height));
    std::vector<png_bytep> rows(static_cast<std::size_t>(img.height));
    for (std::size_t y = 0; y < rows.size(); ++y) rows[y] = img.rgb.data() + row_bytes * y;
    if (!decode_pixels(png, rows.data())) throw_decode_error(path, ctx);
    return img;
}

}  // namespace lat
