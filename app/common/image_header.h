// The size an image file declares in its header (JPEG frame header, PNG IHDR, BMP info header, PNM header),
// read before decoding so that a small file declaring a huge image is refused instead of making the decoder
// allocate gigabytes. readPhoto (common/image_io), which every photo the booth reads goes through, the sim
// camera's included, checks it; the BMP and PNM readers in image_codec.cpp share its header parsing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>

namespace avatarbooth {

enum class ImageFormat { Unknown, Jpeg, Png, Bmp, Pnm };

struct ImageHeader {
    ImageFormat format = ImageFormat::Unknown;
    // As declared (64-bit: a header may declare sizes whose product overflows an int); 0 when the header is cut
    // short or the format has none (a JPEG without a frame header).
    std::int64_t width = 0;
    std::int64_t height = 0;
};

namespace image_header_detail {

inline std::uint32_t bigEndian(const unsigned char* b, std::size_t at, int bytes) {
    std::uint32_t v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | b[at + static_cast<std::size_t>(i)];
    return v;
}

inline std::int32_t littleEndian32(const unsigned char* b, std::size_t at) {
    const std::uint32_t v = static_cast<std::uint32_t>(b[at]) | static_cast<std::uint32_t>(b[at + 1]) << 8 |
                            static_cast<std::uint32_t>(b[at + 2]) << 16 | static_cast<std::uint32_t>(b[at + 3]) << 24;
    return static_cast<std::int32_t>(v);
}

// The next whitespace-separated decimal number of a PNM header (skipping # comments); -1 when there is none.
inline std::int64_t pnmNumber(const unsigned char* b, std::size_t n, std::size_t& at) {
    for (;;) {
        while (at < n && (b[at] == ' ' || b[at] == '\t' || b[at] == '\r' || b[at] == '\n')) ++at;
        if (at < n && b[at] == '#') {
            while (at < n && b[at] != '\n') ++at;
            continue;
        }
        break;
    }
    std::int64_t v = 0;
    std::size_t digits = 0;
    while (at < n && b[at] >= '0' && b[at] <= '9' && digits < 12) {
        v = v * 10 + (b[at++] - '0');
        ++digits;
    }
    return digits ? v : -1;
}

}  // namespace image_header_detail

// What a BMP's headers say of its size and pixel layout: the sides (from 26 bytes on), and the rest from an OS/2
// core header (12 bytes: 16-bit sides, never compressed) or a BITMAPINFOHEADER or later one (40 bytes or more)
// when the data holds them (`layoutKnown`).
struct BmpLayout {
    std::int64_t width = 0, height = 0;  // height without its sign (negative: rows top-down)
    bool layoutKnown = false;
    unsigned bitsPerPixel = 0;
    std::int32_t compression = 0;  // 0: none, 3: bit fields, 1 and 2: RLE
    std::uint32_t pixelsAt = 0;    // the pixel array's offset in the file
};

inline BmpLayout readBmpLayout(const unsigned char* b, std::size_t n) {
    using namespace image_header_detail;
    BmpLayout l;
    if (n < 26) return l;
    const auto littleEndian16 = [&](std::size_t at) { return static_cast<unsigned>(b[at] | b[at + 1] << 8); };
    const std::int32_t headerSize = littleEndian32(b, 14);
    if (headerSize == 12) {
        l.width = littleEndian16(18);
        l.height = littleEndian16(20);
        l.bitsPerPixel = littleEndian16(24);
        l.layoutKnown = true;
    } else {
        l.width = littleEndian32(b, 18);
        l.height = std::abs(std::int64_t{littleEndian32(b, 22)});
        if (headerSize >= 40 && n >= 34) {
            l.bitsPerPixel = littleEndian16(28);
            l.compression = littleEndian32(b, 30);
            l.layoutKnown = true;
        }
    }
    l.pixelsAt = static_cast<std::uint32_t>(littleEndian32(b, 10));
    return l;
}

inline ImageHeader readImageHeader(const unsigned char* b, std::size_t n) {
    using namespace image_header_detail;
    ImageHeader h;
    if (n >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) {
        h.format = ImageFormat::Jpeg;
        std::size_t i = 2;
        while (i + 9 < n) {
            if (b[i] != 0xFF) break;
            const unsigned char marker = b[i + 1];
            if (marker == 0xFF) {
                ++i;
                continue;
            }
            const bool startOfFrame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
            if (startOfFrame) {
                h.width = bigEndian(b, i + 7, 2);
                h.height = bigEndian(b, i + 5, 2);
                break;
            }
            i += 2 + bigEndian(b, i + 2, 2);
        }
    } else if (n >= 8 && b[0] == 0x89 && b[1] == 'P' && b[2] == 'N' && b[3] == 'G') {
        h.format = ImageFormat::Png;
        if (n >= 24) {
            h.width = bigEndian(b, 16, 4);
            h.height = bigEndian(b, 20, 4);
        }
    } else if (n >= 2 && b[0] == 'B' && b[1] == 'M') {
        h.format = ImageFormat::Bmp;
        const BmpLayout layout = readBmpLayout(b, n);
        h.width = layout.width;
        h.height = layout.height;
    } else if (n >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6') {
        h.format = ImageFormat::Pnm;
        std::size_t at = 2;
        const std::int64_t w = pnmNumber(b, n, at);
        const std::int64_t hh = w >= 0 ? pnmNumber(b, n, at) : -1;
        if (w >= 0 && hh >= 0) {
            h.width = w;
            h.height = hh;
        }
    }
    return h;
}

}  // namespace avatarbooth
