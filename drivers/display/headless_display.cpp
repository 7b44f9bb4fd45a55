// Headless display: frames kept in memory, screenshots written as PNG.
#include "drivers/display/headless_display.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"

#include <opencv2/imgproc.hpp>

#include <cstdio>

namespace avatarbooth {

HeadlessDisplay::HeadlessDisplay(const DisplaySettings& settings)
    : panel_(settings.width, settings.height),
      rotation_(rotationFromDegrees(settings.rotation)),
      everyNth_(settings.everyNthFrame),
      framesDir_(settings.framesDir) {
    if (settings.width < 1 || settings.height < 1 || settings.width > 16384 || settings.height > 16384)
        throw BoothError(ErrorKind::BadConfig, "display.width/height",
                         std::to_string(settings.width) + "x" + std::to_string(settings.height) +
                             " is not a screen size (1-16384 pixels each way)");
    if (everyNth_ < 0)
        throw BoothError(ErrorKind::BadConfig, "display.every_nth_frame", "must be 0 (none) or more");
    if (everyNth_ > 0) {
        if (framesDir_.empty())
            throw BoothError(ErrorKind::BadConfig, "display.frames_dir",
                             "is needed to write every " + std::to_string(everyNth_) + "th frame");
        std::error_code ec;
        std::filesystem::create_directories(framesDir_, ec);
        if (ec) throw BoothError(ErrorKind::Output, framesDir_.string(), "cannot create the folder: " + ec.message());
    }
}

void HeadlessDisplay::present(const cv::Mat& bgr) {
    if (bgr.empty() || bgr.type() != CV_8UC3)
        throw BoothError(ErrorKind::Internal, "headless display", "present() needs an 8-bit BGR image");
    const cv::Size want = size();
    if (bgr.size() == want) {
        bgr.copyTo(last_);
    } else {
        // As a screen would: fit, keep the aspect ratio, black around (composeForPanel without a turn).
        last_ = composeForPanel(bgr, want, Rotation::R0);
    }
    ++frames_;
    if (everyNth_ > 0 && frames_ % static_cast<std::uint64_t>(everyNth_) == 0) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%06llu.png", static_cast<unsigned long long>(frames_));
        writeScreenshot(framesDir_ / name);
    }
}

cv::Mat HeadlessDisplay::lastPanelFrame() const {
    if (last_.empty()) return {};
    return composeForPanel(last_, panel_, rotation_);
}

void HeadlessDisplay::writeScreenshot(const std::filesystem::path& path) const {
    if (last_.empty()) throw BoothError(ErrorKind::Internal, path.string(), "no frame was presented yet");
    writeFileAtomically(path, encodeImage(last_, ".png"));
}

std::string HeadlessDisplay::describe() const {
    std::string s = "headless " + std::to_string(panel_.width) + "x" + std::to_string(panel_.height);
    if (rotation_ != Rotation::R0) s += " rotated " + std::to_string(degrees(rotation_));
    if (everyNth_ > 0) s += ", one frame in " + std::to_string(everyNth_) + " written to " + framesDir_.string();
    return s;
}

}  // namespace avatarbooth
