// The screen the kiosk draws on: each frame is a finished BGR image, presented as a whole.
//
// The kiosk composes every screen as a cv::Mat of size() (the viewer's orientation) and calls present(); the
// display turns it by the configured rotation for the panel, scales it to fit (keeping its aspect ratio, black
// bars) and shows it. Implementations: KmsDisplay (the kiosk: EGL on GBM/KMS), WindowDisplay (development: EGL in
// an X11 window), HeadlessDisplay (no screen: keeps frames, writes screenshots). createDisplay() chooses.
#pragma once

#include "drivers/display/display_geometry.h"

#include <opencv2/core.hpp>

#include <chrono>
#include <string>
#include <vector>

namespace avatarbooth {

// A key going down or up on a display with a keyboard (the development window).
struct KeyEvent {
    std::string key;  // X11 keysym name: "space", "Return", "Escape", "r"
    bool pressed = true;
    std::chrono::steady_clock::time_point time;
};

class Display {
public:
    virtual ~Display() = default;
    // Shows `bgr` (8-bit, 3 channels, any size; size() fits exactly) until the next call. Blocks until the frame
    // is on its way to the screen (KMS: the page flip of the previous frame is done), which paces the caller.
    virtual void present(const cv::Mat& bgr) = 0;
    // The size the kiosk should compose its frames at: the panel's size turned by the rotation.
    virtual cv::Size size() const = 0;
    // The rotation applied when presenting.
    virtual Rotation rotation() const = 0;
    // Key events since the last call (empty where there is no keyboard).
    virtual std::vector<KeyEvent> pollKeys() { return {}; }
    // True once the user asked to close the window (the window's close button).
    virtual bool closeRequested() const { return false; }
    // One line for the start-up log: backend, device and mode, e.g. "kms /dev/dri/card1 HDMI-A-1 1920x1080@60".
    virtual std::string describe() const = 0;
};

}  // namespace avatarbooth
