// Choosing a V4L2 format and frame size from what a device offers: a pure function, so it is tested on
// hand-made format lists without a device.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace avatarbooth {

// A frame size a format offers: one size (min == max), or a range stepping by `step` (VIDIOC_ENUM_FRAMESIZES'
// stepwise and continuous kinds).
struct V4l2FrameSize {
    int minWidth = 0, maxWidth = 0, stepWidth = 1;
    int minHeight = 0, maxHeight = 0, stepHeight = 1;
    double maxFps = 0;  // the highest frame rate at this size; 0 = the device does not say

    static V4l2FrameSize discrete(int width, int height, double maxFps = 0) {
        return {width, width, 1, height, height, 1, maxFps};
    }
};

struct V4l2Format {
    std::uint32_t fourcc = 0;  // V4L2 pixel format, e.g. fourccCode('Y','U','Y','V')
    std::string description;   // the driver's name for it
    std::vector<V4l2FrameSize> sizes;
};

struct V4l2FormatChoice {
    std::uint32_t fourcc = 0;
    int width = 0;
    int height = 0;
    double maxFps = 0;  // of the chosen size, 0 when unknown
};

// Picks the format and size for a wanted size and rate (wantedWidth/Height 0: the largest size; wantedFps 0:
// any rate). Only formats we convert (YUYV, MJPEG/JPEG, RGB24, BGR24) are considered. Order of preference:
//   1. a size at least as large as wanted in both directions (larger ones are scaled down by the consumer);
//      if there is none, the largest;
//   2. a rate reaching the wanted fps (a size whose rate is unknown counts as reaching it);
//   3. the exact size, else the smallest of those large enough;
//   4. YUYV, then MJPEG, then RGB/BGR (YUYV needs no decoding and has no compression artefacts).
// Ranges are stepped to the smallest step covering the wanted size. nullopt when no format can be read.
std::optional<V4l2FormatChoice> negotiateV4l2Format(const std::vector<V4l2Format>& formats, int wantedWidth,
                                                    int wantedHeight, double wantedFps);

// "YUYV 640x480@30 1280x720@10; MJPG 1280x720@30" (sizes of ranges as "320x240-1920x1080/8x8").
std::string describeV4l2Formats(const std::vector<V4l2Format>& formats);

}  // namespace avatarbooth
