// Raw buffer conversions: size checks first, then OpenCV's colour conversions and the JPEG decoder of
// common/image_codec (libjpeg-turbo).
#include "drivers/camera/frame_conversion.h"

#include "common/image_codec.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cctype>

namespace avatarbooth {

namespace {

// Bytes needed for `rows` lines of `rowBytes` with `stride` between line starts.
std::size_t bytesNeeded(int rows, std::size_t stride, std::size_t rowBytes) {
    return rows == 0 ? 0 : static_cast<std::size_t>(rows - 1) * stride + rowBytes;
}

// A read-only view as a cv::Mat; OpenCV wants a non-const pointer but the conversions only read it.
cv::Mat view(const std::uint8_t* data, int rows, int cols, int type, std::size_t stride) {
    return cv::Mat(rows, cols, type, const_cast<std::uint8_t*>(data), stride);
}

cv::Mat packedToBgr(const RawFrame& f, int bytesPerPixel, int type, int conversion) {
    if (f.planes.size() != 1) return {};
    const std::size_t rowBytes = static_cast<std::size_t>(f.width) * static_cast<std::size_t>(bytesPerPixel);
    const std::size_t stride = f.stride ? f.stride : rowBytes;
    if (stride < rowBytes || f.planes[0].size() < bytesNeeded(f.height, stride, rowBytes)) return {};
    const cv::Mat src = view(f.planes[0].data(), f.height, f.width, type, stride);
    cv::Mat bgr;
    if (conversion < 0)
        src.copyTo(bgr);
    else
        cv::cvtColor(src, bgr, conversion);
    return bgr;
}

// The planes of a 4:2:0 frame: Y, then either UV (NV12) or U and V (YUV420), with their strides.
struct Planes420 {
    std::span<const std::uint8_t> y, u, v;
    std::size_t yStride = 0, cStride = 0;
};

std::optional<Planes420> split420(const RawFrame& f) {
    const bool nv12 = f.format == RawPixelFormat::NV12;
    Planes420 p;
    p.yStride = f.stride ? f.stride : static_cast<std::size_t>(f.width);
    p.cStride = nv12 ? p.yStride : p.yStride / 2;
    const int cRows = f.height / 2;
    const std::size_t yBytes = static_cast<std::size_t>(f.height) * p.yStride;
    const std::size_t cBytes = static_cast<std::size_t>(cRows) * p.cStride;
    const std::size_t cRowBytes = nv12 ? static_cast<std::size_t>(f.width) : static_cast<std::size_t>(f.width / 2);
    if (p.yStride < static_cast<std::size_t>(f.width) || p.cStride < cRowBytes) return std::nullopt;
    const std::size_t planeCount = nv12 ? 2 : 3;
    if (f.planes.size() == 1) {
        const auto all = f.planes[0];
        if (all.size() < yBytes + (planeCount - 1) * cBytes - (p.cStride - cRowBytes)) return std::nullopt;
        p.y = all.subspan(0, yBytes);
        p.u = all.subspan(yBytes);
        if (!nv12) p.v = all.subspan(yBytes + cBytes);
    } else if (f.planes.size() == planeCount) {
        p.y = f.planes[0];
        p.u = f.planes[1];
        if (!nv12) p.v = f.planes[2];
    } else {
        return std::nullopt;
    }
    if (p.y.size() < bytesNeeded(f.height, p.yStride, static_cast<std::size_t>(f.width)) ||
        p.u.size() < bytesNeeded(cRows, p.cStride, cRowBytes) ||
        (!nv12 && p.v.size() < bytesNeeded(cRows, p.cStride, cRowBytes)))
        return std::nullopt;
    return p;
}

cv::Mat yuv420ToBgr(const RawFrame& f) {
    if (f.width % 2 || f.height % 2) return {};
    const auto p = split420(f);
    if (!p) return {};
    const cv::Mat y = view(p->y.data(), f.height, f.width, CV_8UC1, p->yStride);
    cv::Mat bgr;
    if (f.format == RawPixelFormat::NV12) {
        const cv::Mat uv = view(p->u.data(), f.height / 2, f.width / 2, CV_8UC2, p->cStride);
        cv::cvtColorTwoPlane(y, uv, bgr, cv::COLOR_YUV2BGR_NV12);
        return bgr;
    }
    // OpenCV's I420 conversion wants the three planes back to back without padding.
    cv::Mat i420(f.height * 3 / 2, f.width, CV_8UC1);
    y.copyTo(i420.rowRange(0, f.height));
    const int quarter = f.width / 2;
    auto* out = i420.ptr<std::uint8_t>(f.height);
    for (const auto& plane : {p->u, p->v})
        for (int r = 0; r < f.height / 2; ++r, out += quarter)
            std::copy_n(plane.data() + static_cast<std::size_t>(r) * p->cStride, quarter, out);
    cv::cvtColor(i420, bgr, cv::COLOR_YUV2BGR_I420);
    return bgr;
}

cv::Mat jpegToBgr(const RawFrame& f) {
    if (f.planes.size() != 1) return {};
    auto bytes = f.planes[0];
    // UVC cameras pad the payload with zeros after the end-of-image marker.
    while (!bytes.empty() && bytes.back() == 0) bytes = bytes.first(bytes.size() - 1);
    if (bytes.size() < 4 || bytes[0] != 0xFF || bytes[1] != 0xD8 || bytes[bytes.size() - 2] != 0xFF ||
        bytes[bytes.size() - 1] != 0xD9)
        return {};  // not a JPEG, or cut short: libjpeg would "decode" it as a half-grey picture
    cv::Mat bgr;
    try {
        bgr = decodeImage(bytes.data(), bytes.size());
    } catch (const ImageDecodeError&) {
        return {};  // a damaged frame is dropped; the next one follows in 1/30 s
    }
    if ((f.width && bgr.cols != f.width) || (f.height && bgr.rows != f.height)) return {};
    return bgr;
}

}  // namespace

const char* rawPixelFormatName(RawPixelFormat format) {
    switch (format) {
        case RawPixelFormat::YUYV: return "YUYV";
        case RawPixelFormat::MJPEG: return "MJPEG";
        case RawPixelFormat::BGR24: return "BGR24";
        case RawPixelFormat::RGB24: return "RGB24";
        case RawPixelFormat::BGRX32: return "BGRX32";
        case RawPixelFormat::RGBX32: return "RGBX32";
        case RawPixelFormat::NV12: return "NV12";
        case RawPixelFormat::YUV420: return "YUV420";
    }
    return "?";
}

cv::Mat rawFrameToBgr(const RawFrame& f) {
    // Only a JPEG may leave its size open (0): it carries its own.
    if (f.width < 0 || f.height < 0) return {};
    if (f.format != RawPixelFormat::MJPEG && (f.width == 0 || f.height == 0)) return {};
    switch (f.format) {
        case RawPixelFormat::YUYV:
            if (f.width % 2) return {};
            return packedToBgr(f, 2, CV_8UC2, cv::COLOR_YUV2BGR_YUYV);
        case RawPixelFormat::MJPEG: return jpegToBgr(f);
        case RawPixelFormat::BGR24: return packedToBgr(f, 3, CV_8UC3, -1);
        case RawPixelFormat::RGB24: return packedToBgr(f, 3, CV_8UC3, cv::COLOR_RGB2BGR);
        case RawPixelFormat::BGRX32: return packedToBgr(f, 4, CV_8UC4, cv::COLOR_BGRA2BGR);
        case RawPixelFormat::RGBX32: return packedToBgr(f, 4, CV_8UC4, cv::COLOR_RGBA2BGR);
        case RawPixelFormat::NV12:
        case RawPixelFormat::YUV420: return yuv420ToBgr(f);
    }
    return {};
}

cv::Mat yuyvToBgr(std::span<const std::uint8_t> bytes, int width, int height, std::size_t bytesPerLine) {
    return rawFrameToBgr({RawPixelFormat::YUYV, width, height, bytesPerLine, {bytes}});
}

cv::Mat mjpegToBgr(std::span<const std::uint8_t> bytes, int width, int height) {
    return rawFrameToBgr({RawPixelFormat::MJPEG, width, height, 0, {bytes}});
}

std::string fourccName(std::uint32_t fourcc) {
    std::string name;
    for (int i = 0; i < 4; ++i) {
        const auto c = static_cast<char>((fourcc >> (8 * i)) & 0xFF);
        name += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
    }
    return name;
}

std::optional<RawPixelFormat> rawFormatFromV4l2(std::uint32_t fourcc) {
    switch (fourcc) {
        case fourccCode('Y', 'U', 'Y', 'V'): return RawPixelFormat::YUYV;
        case fourccCode('M', 'J', 'P', 'G'):
        case fourccCode('J', 'P', 'E', 'G'): return RawPixelFormat::MJPEG;
        case fourccCode('R', 'G', 'B', '3'): return RawPixelFormat::RGB24;
        case fourccCode('B', 'G', 'R', '3'): return RawPixelFormat::BGR24;
        default: return std::nullopt;
    }
}

std::optional<RawPixelFormat> rawFormatFromLibcamera(const std::string& name) {
    if (name == "RGB888") return RawPixelFormat::BGR24;
    if (name == "BGR888") return RawPixelFormat::RGB24;
    if (name == "XRGB8888") return RawPixelFormat::BGRX32;
    if (name == "XBGR8888") return RawPixelFormat::RGBX32;
    if (name == "YUYV") return RawPixelFormat::YUYV;
    if (name == "NV12") return RawPixelFormat::NV12;
    if (name == "YUV420") return RawPixelFormat::YUV420;
    if (name == "MJPEG") return RawPixelFormat::MJPEG;
    return std::nullopt;
}

}  // namespace avatarbooth
