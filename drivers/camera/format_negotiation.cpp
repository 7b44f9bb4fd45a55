// Format negotiation: score every (format, size) candidate and keep the best.
#include "drivers/camera/format_negotiation.h"

#include "drivers/camera/frame_conversion.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <tuple>

namespace avatarbooth {

namespace {

// The smallest value of min + k*step that is >= wanted, within [min, max]; max's step below it when none is.
int stepToCover(int wanted, int min, int max, int step) {
    if (wanted <= min) return min;
    step = std::max(step, 1);
    const long long k = (static_cast<long long>(wanted) - min + step - 1) / step;
    const long long value = min + k * step;
    if (value <= max) return static_cast<int>(value);
    return static_cast<int>(min + (static_cast<long long>(max) - min) / step * step);
}

int formatRank(std::uint32_t fourcc) {
    switch (*rawFormatFromV4l2(fourcc)) {
        case RawPixelFormat::YUYV: return 0;
        case RawPixelFormat::MJPEG: return 1;
        default: return 2;
    }
}

std::string fpsText(double fps) {
    std::ostringstream out;
    out << fps;
    return out.str();
}

}  // namespace

std::optional<V4l2FormatChoice> negotiateV4l2Format(const std::vector<V4l2Format>& formats, int wantedWidth,
                                                    int wantedHeight, double wantedFps) {
    const bool largest = wantedWidth <= 0 || wantedHeight <= 0;
    // Lower is better, compared in order.
    using Key = std::tuple<int, int, int, long long, int>;
    std::optional<std::pair<Key, V4l2FormatChoice>> best;
    for (const auto& format : formats) {
        if (!rawFormatFromV4l2(format.fourcc)) continue;
        for (const auto& size : format.sizes) {
            if (size.maxWidth <= 0 || size.maxHeight <= 0) continue;
            const int w = largest ? size.maxWidth : stepToCover(wantedWidth, size.minWidth, size.maxWidth, size.stepWidth);
            const int h = largest ? size.maxHeight : stepToCover(wantedHeight, size.minHeight, size.maxHeight, size.stepHeight);
            const long long area = static_cast<long long>(w) * h;
            const bool bigEnough = largest || (w >= wantedWidth && h >= wantedHeight);
            // 29.97 counts as 30.
            const bool fpsOk = wantedFps <= 0 || size.maxFps <= 0 || size.maxFps >= wantedFps * 0.99;
            const bool exact = !largest && w == wantedWidth && h == wantedHeight;
            const long long areaKey = largest || !bigEnough ? -area : area;
            const Key key{bigEnough ? 0 : 1, fpsOk ? 0 : 1, exact ? 0 : 1, areaKey, formatRank(format.fourcc)};
            if (!best || key < best->first) best = {{key, V4l2FormatChoice{format.fourcc, w, h, size.maxFps}}};
        }
    }
    if (!best) return std::nullopt;
    return best->second;
}

std::string describeV4l2Formats(const std::vector<V4l2Format>& formats) {
    std::string out;
    for (const auto& format : formats) {
        if (!out.empty()) out += "; ";
        out += fourccName(format.fourcc);
        for (const auto& s : format.sizes) {
            out += " " + std::to_string(s.minWidth) + "x" + std::to_string(s.minHeight);
            if (s.minWidth != s.maxWidth || s.minHeight != s.maxHeight)
                out += "-" + std::to_string(s.maxWidth) + "x" + std::to_string(s.maxHeight) + "/" +
                       std::to_string(s.stepWidth) + "x" + std::to_string(s.stepHeight);
            if (s.maxFps > 0) out += "@" + fpsText(s.maxFps);
        }
    }
    return out.empty() ? "no formats" : out;
}

}  // namespace avatarbooth
