// The development screen: EGL + OpenGL ES in an X11 window of the panel's size, with the keyboard as buttons.
#pragma once

#include "drivers/display/display.h"
#include "drivers/display/display_settings.h"

#include <memory>

namespace avatarbooth {

class WindowDisplay final : public Display {
public:
    // Opens a window of settings.width x height on $DISPLAY. Throws BoothError(Device) when $DISPLAY is unset or
    // the X server cannot be reached, naming it.
    explicit WindowDisplay(const DisplaySettings& settings);
    ~WindowDisplay() override;

    // Draws into the window (letterboxed to its current size when it was resized) and swaps.
    void present(const cv::Mat& bgr) override;
    cv::Size size() const override { return rotatedSize(panel_, rotation_); }
    Rotation rotation() const override { return rotation_; }
    // Keys pressed and released in the window since the last call; holding a key gives one press.
    std::vector<KeyEvent> pollKeys() override;
    bool closeRequested() const override { return closeRequested_; }
    std::string describe() const override;

private:
    struct State;
    std::unique_ptr<State> state_;
    cv::Size panel_;
    Rotation rotation_;
    bool closeRequested_ = false;
};

}  // namespace avatarbooth
