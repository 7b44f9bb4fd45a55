// Raw camera buffers to BGR images: pure functions over bytes, shared by the V4L2 and libcamera backends.
//
// YUV is read as ITU-R BT.601 with limited range (Y 16-235), what UVC cameras and V4L2 use by default.
#pragma once

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace avatarbooth {

// Layouts named by their bytes in memory (not by V4L2 or DRM fourcc, which disagree about RGB order).
enum class RawPixelFormat {
    YUYV,    // 4:2:2 packed Y0 U Y1 V
    MJPEG,   // one JPEG image per frame (UVC cameras may leave out the Huffman tables)
    BGR24,   // B G R
    RGB24,   // R G B
    BGRX32,  // B G R X
    RGBX32,  // R G B X
    NV12,    // 4:2:0, a Y plane then one interleaved U V plane (same stride)
    YUV420,  // 4:2:0, Y, U, V planes (chroma stride half the luma stride)
};

const char* rawPixelFormatName(RawPixelFormat format);

// One frame as a driver hands it over. Planar formats take one span per plane, or a single span holding all
// planes back to back (then the planes follow each other without padding beyond the strides).
struct RawFrame {
    RawPixelFormat format = RawPixelFormat::YUYV;
    int width = 0;
    int height = 0;
    std::size_t stride = 0;  // bytes per line of the first plane; 0 = tightly packed
    std::vector<std::span<const std::uint8_t>> planes;
};

// The frame as 8-bit BGR (a new image, never a view into the raw bytes). Returns an empty image when the bytes
// cannot be a frame of that format and size (too few bytes for the size and stride, odd width for YUYV, a JPEG
// that does not decode, is truncated (no end-of-image marker) or has another size): the callers drop such frames.
cv::Mat rawFrameToBgr(const RawFrame& frame);

// The two conversions the V4L2 backend needs most, as shorthands for rawFrameToBgr.
cv::Mat yuyvToBgr(std::span<const std::uint8_t> bytes, int width, int height, std::size_t bytesPerLine = 0);
// width/height 0: accept whatever size the JPEG has.
cv::Mat mjpegToBgr(std::span<const std::uint8_t> bytes, int width = 0, int height = 0);

// V4L2 fourcc codes (as in linux/videodev2.h) without needing that header.
constexpr std::uint32_t fourccCode(char a, char b, char c, char d) {
    return static_cast<std::uint32_t>(static_cast<unsigned char>(a)) |
           (static_cast<std::uint32_t>(static_cast<unsigned char>(b)) << 8) |
           (static_cast<std::uint32_t>(static_cast<unsigned char>(c)) << 16) |
           (static_cast<std::uint32_t>(static_cast<unsigned char>(d)) << 24);
}
// "YUYV", "MJPG"...; unprintable bytes as '?'.
std::string fourccName(std::uint32_t fourcc);

// The layout of a V4L2 pixel format we can convert (YUYV, MJPG, JPEG, RGB3, BGR3); nullopt for the others.
std::optional<RawPixelFormat> rawFormatFromV4l2(std::uint32_t fourcc);
// The layout of a libcamera pixel format by its name (PixelFormat::toString(): "RGB888", "XRGB8888", "YUYV",
// "NV12", "YUV420", "MJPEG"...); nullopt for the others. libcamera's names follow DRM, so "RGB888" is B G R in
// memory.
std::optional<RawPixelFormat> rawFormatFromLibcamera(const std::string& name);

}  // namespace avatarbooth
