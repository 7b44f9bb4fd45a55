// The size an image file declares in its header (JPEG frame header, PNG IHDR, BMP info header, PNM header),
// read before decoding so that a small file declaring a huge image is refused instead of making the decoder
// allocate gigabytes. readPhoto (common/image_io), which every photo the booth reads goes through, the sim
// camera's included, checks it; the PNM reader in image_codec.cpp shares its number parser.
#pragma once

#include <cstddef>
#include <cstdint>

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
        if (n >= 26 && littleEndian32(b, 14) == 12) {
            // OS/2 BITMAPCOREHEADER: 16-bit sides.
            h.width = b[18] | b[19] << 8;
            h.height = b[20] | b[21] << 8;
        } else if (n >= 26) {
            // BITMAPINFOHEADER and later; a negative height means top-down rows.
            h.width = littleEndian32(b, 18);
            const std::int64_t height = littleEndian32(b, 22);
            h.height = height < 0 ? -height : height;
        }
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
