// Headless display: no screen; keeps the last frame, counts frames, writes screenshots (and every N-th frame).
// Works everywhere: the simulated booth and the tests use it.
#pragma once

#include "drivers/display/display.h"
#include "drivers/display/display_settings.h"

#include <cstdint>
#include <filesystem>

namespace avatarbooth {

class HeadlessDisplay final : public Display {
public:
    // Panel size and rotation from the settings; BoothError(BadConfig) for a bad rotation, size or frame dump.
    explicit HeadlessDisplay(const DisplaySettings& settings);

    // Keeps a copy of the frame (scaled to fit size() when it differs); every N-th frame is also written.
    void present(const cv::Mat& bgr) override;
    cv::Size size() const override { return rotatedSize(panel_, rotation_); }
    Rotation rotation() const override { return rotation_; }
    std::string describe() const override;

    // The last frame as presented (the viewer's orientation, size()); empty before the first.
    const cv::Mat& lastFrame() const { return last_; }
    // What a panel mounted with the configured rotation would show (panel size).
    cv::Mat lastPanelFrame() const;
    // Frames presented so far.
    std::uint64_t frameCount() const { return frames_; }
    // Writes the last frame (as presented) as a PNG, atomically (mode 0600). BoothError(Output) when it cannot be
    // written, (Internal) when nothing was presented yet.
    void writeScreenshot(const std::filesystem::path& path) const;

private:
    cv::Size panel_;
    Rotation rotation_;
    int everyNth_ = 0;
    std::filesystem::path framesDir_;
    cv::Mat last_;
    std::uint64_t frames_ = 0;
};

}  // namespace avatarbooth
