// libjpeg and libpng report errors by longjmp. Each call into them therefore runs in a small function that holds
// no C++ object of its own (a longjmp would skip its destructor): everything it touches lives in a context struct
// its caller owns, and it returns false when the library jumped back with an error.
#include "common/image_codec.h"

#include "common/image_header.h"

#include <opencv2/imgproc.hpp>

// The C libraries after the C++ ones: jpeglib.h needs <cstdio>'s FILE and size_t first.
#include <algorithm>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <jpeglib.h>
#include <libexif/exif-data.h>
#include <png.h>
#include <stb_image.h>
#include <zlib.h>

namespace avatarbooth {

namespace {

// ---- JPEG (libjpeg-turbo) ----

struct JpegErrors {
    jpeg_error_mgr base;  // first: libjpeg hands back a pointer to it
    std::jmp_buf jump;
    char message[JMSG_LENGTH_MAX];
};

extern "C" void jpegFail(j_common_ptr cinfo) {
    auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
    (*cinfo->err->format_message)(cinfo, errors->message);
    std::longjmp(errors->jump, 1);
}

// libjpeg's warnings (say, "premature end of data segment" in a damaged scan) go to stderr by default; the
// picture is still decoded, as OpenCV decoded it, and readers check the end-of-image marker themselves.
extern "C" void jpegMessage(j_common_ptr, int) {}

JpegErrors* jpegErrors(JpegErrors& errors) {
    jpeg_std_error(&errors.base);
    errors.base.error_exit = jpegFail;
    errors.base.emit_message = jpegMessage;
    errors.message[0] = '\0';
    return &errors;
}

// The EXIF orientation (1-8; 1 when there is none) from the APP1 markers libjpeg kept.
int exifOrientation(const jpeg_decompress_struct& cinfo) {
    for (jpeg_saved_marker_ptr m = cinfo.marker_list; m != nullptr; m = m->next) {
        if (m->marker != JPEG_APP0 + 1 || m->data_length < 6 || std::memcmp(m->data, "Exif\0\0", 6) != 0) continue;
        ExifData* exif = exif_data_new_from_data(m->data, m->data_length);
        if (exif == nullptr) return 1;
        int orientation = 1;
        ExifEntry* entry = exif_content_get_entry(exif->ifd[EXIF_IFD_0], EXIF_TAG_ORIENTATION);
        if (entry != nullptr && entry->format == EXIF_FORMAT_SHORT && entry->components >= 1 && entry->size >= 2)
            orientation = exif_get_short(entry->data, exif_data_get_byte_order(exif));
        exif_data_unref(exif);
        return orientation >= 1 && orientation <= 8 ? orientation : 1;
    }
    return 1;
}

// Turns the stored pixels upright as EXIF orientation `o` says (the same flips and transposes as OpenCV's imread).
void applyOrientation(cv::Mat& image, int o) {
    if (o >= 5) cv::transpose(image, image);  // 5-8: the camera was held sideways
    switch (o) {
        case 2: case 6: cv::flip(image, image, 1); break;
        case 3: case 7: cv::flip(image, image, -1); break;
        case 4: case 8: cv::flip(image, image, 0); break;
        default: break;
    }
}

struct JpegDecode {
    jpeg_decompress_struct cinfo{};
    JpegErrors errors{};
    const unsigned char* data = nullptr;
    std::size_t size = 0;
    bool cmyk = false;
    int orientation = 1;
    cv::Mat image;
};

bool runJpegDecode(JpegDecode* d) {
    d->cinfo.err = &jpegErrors(d->errors)->base;
    if (setjmp(d->errors.jump)) return false;
    jpeg_create_decompress(&d->cinfo);
    jpeg_mem_src(&d->cinfo, d->data, static_cast<unsigned long>(d->size));
    jpeg_save_markers(&d->cinfo, JPEG_APP0 + 1, 0xFFFF);
    jpeg_read_header(&d->cinfo, TRUE);
    if (d->cinfo.num_components == 4) {  // CMYK or YCCK: print files, never a camera's
        d->cmyk = true;
        return true;
    }
    // libjpeg-turbo writes BGR directly (grey is replicated); MJPEG frames without Huffman tables get the
    // standard ones.
    d->cinfo.out_color_space = JCS_EXT_BGR;
    jpeg_start_decompress(&d->cinfo);
    d->image.create(static_cast<int>(d->cinfo.output_height), static_cast<int>(d->cinfo.output_width), CV_8UC3);
    while (d->cinfo.output_scanline < d->cinfo.output_height) {
        JSAMPROW row = d->image.ptr(static_cast<int>(d->cinfo.output_scanline));
        jpeg_read_scanlines(&d->cinfo, &row, 1);
    }
    d->orientation = exifOrientation(d->cinfo);
    jpeg_finish_decompress(&d->cinfo);
    return true;
}

cv::Mat decodeJpeg(const unsigned char* data, std::size_t size) {
    JpegDecode d;
    d.data = data;
    d.size = size;
    const bool ok = runJpegDecode(&d);
    jpeg_destroy_decompress(&d.cinfo);
    if (!ok) throw ImageDecodeError(std::string("JPEG data cannot be decoded: ") + d.errors.message);
    if (d.cmyk) throw ImageDecodeError("is a CMYK JPEG (a print file); save it as an RGB JPEG");
    applyOrientation(d.image, d.orientation);
    return std::move(d.image);
}

struct JpegEncode {
    jpeg_compress_struct cinfo{};
    JpegErrors errors{};
    const cv::Mat* image = nullptr;
    int quality = 90;
    unsigned char* bytes = nullptr;
    unsigned long size = 0;
};

bool runJpegEncode(JpegEncode* e) {
    e->cinfo.err = &jpegErrors(e->errors)->base;
    if (setjmp(e->errors.jump)) return false;
    jpeg_create_compress(&e->cinfo);
    jpeg_mem_dest(&e->cinfo, &e->bytes, &e->size);
    e->cinfo.image_width = static_cast<JDIMENSION>(e->image->cols);
    e->cinfo.image_height = static_cast<JDIMENSION>(e->image->rows);
    e->cinfo.input_components = e->image->channels();
    e->cinfo.in_color_space = e->image->channels() == 1 ? JCS_GRAYSCALE : JCS_EXT_BGR;
    jpeg_set_defaults(&e->cinfo);
    jpeg_set_quality(&e->cinfo, e->quality, TRUE);
    jpeg_start_compress(&e->cinfo, TRUE);
    while (e->cinfo.next_scanline < e->cinfo.image_height) {
        JSAMPROW row = const_cast<JSAMPROW>(e->image->ptr(static_cast<int>(e->cinfo.next_scanline)));
        jpeg_write_scanlines(&e->cinfo, &row, 1);
    }
    jpeg_finish_compress(&e->cinfo);
    return true;
}

// ---- PNG (libpng) ----

struct PngIo {
    const unsigned char* data = nullptr;  // reading: the file's bytes and how far the decoder got
    std::size_t size = 0, at = 0;
    std::string out;  // writing
    char message[200] = {};
};

extern "C" void pngFail(png_structp png, png_const_charp message) {
    auto* io = static_cast<PngIo*>(png_get_error_ptr(png));
    std::snprintf(io->message, sizeof io->message, "%s", message);
    png_longjmp(png, 1);
}

extern "C" void pngWarning(png_structp, png_const_charp) {}  // ancillary-chunk complaints: the pixels are fine

extern "C" void pngRead(png_structp png, png_bytep out, png_size_t n) {
    auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
    if (n > io->size - io->at) png_error(png, "the data ends early (a truncated file)");
    std::memcpy(out, io->data + io->at, n);
    io->at += n;
}

extern "C" void pngWrite(png_structp png, png_bytep data, png_size_t n) {
    static_cast<PngIo*>(png_get_io_ptr(png))->out.append(reinterpret_cast<const char*>(data), n);
}

extern "C" void pngFlush(png_structp) {}

struct PngDecode {
    PngIo io;
    png_structp png = nullptr;
    png_infop info = nullptr;
    cv::Mat image;
    std::vector<png_bytep> rows;
    bool alpha = false;  // BGRA out: the file's alpha (or tRNS), opaque where it has none
};

bool runPngDecode(PngDecode* d) {
    if (setjmp(png_jmpbuf(d->png))) return false;
    png_set_read_fn(d->png, &d->io, pngRead);
    png_read_info(d->png, d->info);
    png_uint_32 width = 0, height = 0;
    int depth = 0, colour = 0;
    png_get_IHDR(d->png, d->info, &width, &height, &depth, &colour, nullptr, nullptr, nullptr);
    // To 8-bit BGR as OpenCV's imread makes it: the high byte of 16-bit samples, palettes and low-depth grey
    // expanded, alpha (and tRNS transparency) dropped, grey replicated.
    if (depth == 16) png_set_strip_16(d->png);
    if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(d->png);
    if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(d->png);
    if (d->alpha) {
        if (png_get_valid(d->png, d->info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(d->png);
        else if (!(colour & PNG_COLOR_MASK_ALPHA)) png_set_add_alpha(d->png, 0xFF, PNG_FILLER_AFTER);
    } else if (colour & PNG_COLOR_MASK_ALPHA) {
        png_set_strip_alpha(d->png);
    }
    if (colour == PNG_COLOR_TYPE_GRAY || colour == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(d->png);
    png_set_bgr(d->png);
    png_set_interlace_handling(d->png);
    png_read_update_info(d->png, d->info);
    const int channels = d->alpha ? 4 : 3;
    if (png_get_rowbytes(d->png, d->info) != static_cast<png_size_t>(width) * channels)
        png_error(d->png, "an unexpected pixel layout");
    d->image.create(static_cast<int>(height), static_cast<int>(width), d->alpha ? CV_8UC4 : CV_8UC3);
    d->rows.resize(height);
    for (png_uint_32 y = 0; y < height; ++y) d->rows[y] = d->image.ptr(static_cast<int>(y));
    png_read_image(d->png, d->rows.data());
    png_read_end(d->png, nullptr);
    return true;
}

cv::Mat decodePng(const unsigned char* data, std::size_t size, bool alpha = false) {
    PngDecode d;
    d.alpha = alpha;
    d.io.data = data;
    d.io.size = size;
    d.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &d.io, pngFail, pngWarning);
    if (d.png != nullptr) d.info = png_create_info_struct(d.png);
    if (d.info == nullptr) {
        png_destroy_read_struct(&d.png, nullptr, nullptr);
        throw ImageDecodeError("PNG: out of memory");
    }
    const bool ok = runPngDecode(&d);
    png_destroy_read_struct(&d.png, &d.info, nullptr);
    if (!ok) throw ImageDecodeError(std::string("PNG data cannot be decoded: ") + d.io.message);
    return std::move(d.image);
}

struct PngEncode {
    PngIo io;
    png_structp png = nullptr;
    png_infop info = nullptr;
    const cv::Mat* image = nullptr;
    std::vector<png_bytep> rows;
};

bool runPngEncode(PngEncode* e) {
    if (setjmp(png_jmpbuf(e->png))) return false;
    png_set_write_fn(e->png, &e->io, pngWrite, pngFlush);
    const int channels = e->image->channels();
    png_set_IHDR(e->png, e->info, static_cast<png_uint_32>(e->image->cols), static_cast<png_uint_32>(e->image->rows), 8,
                 channels == 1 ? PNG_COLOR_TYPE_GRAY : channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGB_ALPHA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    // OpenCV's defaults for PNG: zlib's fastest level with run-length matching and the "sub" filter -- a 720p
    // screenshot in about 15 ms where zlib's default level takes several times that.
    png_set_filter(e->png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_compression_level(e->png, Z_BEST_SPEED);
    png_set_compression_strategy(e->png, Z_RLE);
    png_write_info(e->png, e->info);
    if (channels >= 3) png_set_bgr(e->png);
    png_write_image(e->png, e->rows.data());
    png_write_end(e->png, nullptr);
    return true;
}

void checkEncodable(const cv::Mat& image, const char* format) {
    if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
        throw std::runtime_error(std::string("an image to write as ") + format +
                                 " must be 8-bit grey, BGR or BGRA and not empty");
}

// ---- BMP (stb_image) ----

// The bytes an uncompressed (or bit-field) BMP needs by its header, the kinds cameras and editors write; 0 when
// the header is another kind (stb_image refuses RLE itself) or too short to say.
std::uint64_t bmpDeclaredBytes(const unsigned char* data, std::size_t size) {
    const BmpLayout l = readBmpLayout(data, size);
    if (!l.layoutKnown || (l.compression != 0 && l.compression != 3) || l.width <= 0 || l.height == 0 ||
        l.bitsPerPixel == 0 || l.bitsPerPixel > 32)
        return 0;
    const std::uint64_t rowBytes = (static_cast<std::uint64_t>(l.width) * l.bitsPerPixel + 31) / 32 * 4;  // 4-byte rows
    const auto rows = static_cast<std::uint64_t>(l.height);
    if (rows > (UINT64_MAX - l.pixelsAt) / rowBytes) return UINT64_MAX;  // sides up to 2^31: the product may overflow
    return l.pixelsAt + rowBytes * rows;
}

cv::Mat decodeBmp(const unsigned char* data, std::size_t size) {
    if (size > static_cast<std::size_t>(INT32_MAX)) throw ImageDecodeError("BMP: the file is too large");
    // stb_image fills the rows of a BMP cut short with black and says nothing, so the length is checked first.
    if (const std::uint64_t declared = bmpDeclaredBytes(data, size); declared > size)
        throw ImageDecodeError("BMP data is truncated: its header declares " + std::to_string(declared) +
                               " bytes, the file has " + std::to_string(size));
    int width = 0, height = 0, channels = 0;
    unsigned char* rgb = stbi_load_from_memory(data, static_cast<int>(size), &width, &height, &channels, 3);
    if (rgb == nullptr) throw ImageDecodeError(std::string("BMP data cannot be decoded: ") + stbi_failure_reason());
    if (width <= 0 || height <= 0) {
        stbi_image_free(rgb);
        throw ImageDecodeError("BMP data cannot be decoded: its header declares no pixels");
    }
    cv::Mat bgr;
    cv::cvtColor(cv::Mat(height, width, CV_8UC3, rgb), bgr, cv::COLOR_RGB2BGR);
    stbi_image_free(rgb);
    return bgr;
}

// ---- Binary PNM (P5 grey, P6 colour), read here ----
// Not with stb_image: Debian bookworm's copy (git 2022-09-08) reads past its buffer when a PNM with more than 8
// bits a sample (maxval over 255) is turned into three channels (found by fuzz_photo), takes those samples in the
// machine's byte order instead of PNM's big-endian one, ignores a maxval other than 255, and hands out
// uninitialised pixels for a file cut short. The format is a text header and raw samples (netpbm's pam(5) and
// pgm(5) pages), so reading it here takes less code than working around all four.
// Samples scale to 0-255 by maxval, rounded (a maxval of 15 is not a dark picture); with maxval 65535 the high
// byte is kept, as for 16-bit PNGs and as imread does. Samples above maxval count as maxval.
cv::Mat decodePnm(const unsigned char* data, std::size_t size) {
    using image_header_detail::pnmNumber;
    const bool colour = data[1] == '6';
    const auto isSpace = [](unsigned char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
    std::size_t at = 2;
    if (at >= size || !isSpace(data[at])) throw ImageDecodeError("PNM data cannot be decoded: no space after its P5/P6");
    const std::int64_t width = pnmNumber(data, size, at);
    const std::int64_t height = width >= 0 ? pnmNumber(data, size, at) : -1;
    const std::int64_t maxval = height >= 0 ? pnmNumber(data, size, at) : -1;
    if (maxval < 0 || at >= size || !isSpace(data[at]))
        throw ImageDecodeError("PNM data cannot be decoded: its header (width, height, maxval) is cut short or damaged");
    ++at;  // exactly one whitespace byte ends the header; the samples start after it
    if (width <= 0 || height <= 0) throw ImageDecodeError("PNM data cannot be decoded: its header declares no pixels");
    if (maxval < 1 || maxval > 65535)
        throw ImageDecodeError("PNM data cannot be decoded: its maxval " + std::to_string(maxval) + " is not 1-65535");

    const std::size_t channels = colour ? 3 : 1, sampleBytes = maxval > 255 ? 2 : 1;
    const std::size_t left = size - at;
    // Every pixel takes at least one byte, so each side is at most `left` and the product cannot overflow.
    const auto w = static_cast<std::uint64_t>(width), h = static_cast<std::uint64_t>(height);
    if (w > left || h > left || w * h > left / (channels * sampleBytes))
        throw ImageDecodeError("PNM data is truncated: its header declares " + std::to_string(width) + "x" +
                               std::to_string(height) + " but only " + std::to_string(left) + " bytes of samples follow");

    // 0..maxval to 0..255, once for every possible sample value (at most 64 Ki entries).
    std::vector<unsigned char> to8(static_cast<std::size_t>(sampleBytes == 2 ? 65536 : 256));
    for (std::size_t v = 0; v < to8.size(); ++v) {
        const std::uint64_t m = static_cast<std::uint64_t>(maxval), s = std::min<std::uint64_t>(v, m);
        to8[v] = static_cast<unsigned char>(m == 65535 ? s >> 8 : (s * 255 + m / 2) / m);
    }
    cv::Mat bgr(static_cast<int>(height), static_cast<int>(width), CV_8UC3);
    const unsigned char* in = data + at;
    for (int y = 0; y < bgr.rows; ++y) {
        auto* out = bgr.ptr<unsigned char>(y);
        for (int x = 0; x < bgr.cols; ++x, out += 3) {
            unsigned char rgb[3];
            for (std::size_t c = 0; c < channels; ++c, in += sampleBytes)
                rgb[c] = to8[sampleBytes == 2 ? (std::size_t{in[0]} << 8 | in[1]) : in[0]];
            if (!colour) rgb[1] = rgb[2] = rgb[0];
            out[0] = rgb[2];
            out[1] = rgb[1];
            out[2] = rgb[0];
        }
    }
    return bgr;
}

}  // namespace

cv::Mat decodeImage(const unsigned char* data, std::size_t size) {
    static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    if (size >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF) return decodeJpeg(data, size);
    if (size >= 8 && std::memcmp(data, kPng, 8) == 0) return decodePng(data, size);
    if (size >= 2 && data[0] == 'B' && data[1] == 'M') return decodeBmp(data, size);
    if (size >= 2 && data[0] == 'P' && (data[1] == '5' || data[1] == '6')) return decodePnm(data, size);
    if (size >= 2 && data[0] == 'P' && data[1] >= '1' && data[1] <= '4')
        throw ImageDecodeError("is a text or 1-bit PNM (P1-P4); save it as binary PPM (P6), PNG or JPEG");
    throw ImageDecodeError("is not a JPEG, PNG, BMP or PNM image");
}

cv::Mat decodeImageWithAlpha(const unsigned char* data, std::size_t size) {
    static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    if (size >= 8 && std::memcmp(data, kPng, 8) == 0) return decodePng(data, size, true);
    cv::Mat bgra;
    cv::cvtColor(decodeImage(data, size), bgra, cv::COLOR_BGR2BGRA);
    return bgra;
}

std::string encodeJpeg(const cv::Mat& image, int quality) {
    checkEncodable(image, "JPEG");
    cv::Mat bgr;
    if (image.channels() == 4) cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
    JpegEncode e;
    e.image = image.channels() == 4 ? &bgr : &image;
    e.quality = std::clamp(quality, 1, 100);
    const bool ok = runJpegEncode(&e);
    std::string bytes = ok ? std::string(reinterpret_cast<const char*>(e.bytes), e.size) : std::string();
    jpeg_destroy_compress(&e.cinfo);
    std::free(e.bytes);  // jpeg_mem_dest's buffer is malloc'd and left to the caller
    if (!ok) throw std::runtime_error(std::string("an image could not be written as JPEG: ") + e.errors.message);
    return bytes;
}

std::string encodePng(const cv::Mat& image) {
    checkEncodable(image, "PNG");
    PngEncode e;
    e.image = &image;
    e.rows.resize(static_cast<std::size_t>(image.rows));
    for (int y = 0; y < image.rows; ++y) e.rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(image.ptr(y));
    e.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &e.io, pngFail, pngWarning);
    if (e.png != nullptr) e.info = png_create_info_struct(e.png);
    if (e.info == nullptr) {
        png_destroy_write_struct(&e.png, nullptr);
        throw std::runtime_error("an image could not be written as PNG: out of memory");
    }
    const bool ok = runPngEncode(&e);
    png_destroy_write_struct(&e.png, &e.info);
    if (!ok) throw std::runtime_error(std::string("an image could not be written as PNG: ") + e.io.message);
    return std::move(e.io.out);
}

}  // namespace avatarbooth
