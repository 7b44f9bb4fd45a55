// The kiosk's screen: EGL + OpenGL ES on a GBM surface, shown with KMS page flips (no X, no Wayland).
#pragma once

#include "drivers/display/display.h"
#include "drivers/display/display_settings.h"

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

namespace avatarbooth {

class KmsDisplay final : public Display {
public:
    // The kmscube sequence: finds the DRM device, a connected connector, its preferred mode and a CRTC; creates
    // the GBM device and surface, EGL on them and the quad presenter. Throws BoothError(Device): "no DRM device"
    // when there is no /dev/dri/card*, and names the device or connector otherwise (none connected, the screen is
    // held by another program, ...).
    explicit KmsDisplay(const DisplaySettings& settings);
    ~KmsDisplay() override;

    // Draws, swaps, puts the new buffer on screen (mode set at the first frame, page flips afterwards) and waits
    // for the flip, so frames are paced by the screen's refresh. Throws BoothError(Device) when the screen was
    // disconnected (the connector's status: a cable pulled) or the device is gone (ENODEV), naming which.
    void present(const cv::Mat& bgr) override;
    cv::Size size() const override;
    Rotation rotation() const override { return rotation_; }
    std::string describe() const override;

    // The refresh that showed the last flipped frame: the kernel's vblank count and time (steady_clock, which is
    // the kernel's CLOCK_MONOTONIC). Zero before the second frame (the first is a mode set, not a flip).
    struct Flip {
        std::uint32_t sequence = 0;
        std::chrono::steady_clock::time_point time;
    };
    Flip lastFlip() const;
    // The mode's exact refresh rate (pixel clock over the total frame), e.g. 59.94 for a "60 Hz" mode.
    double refreshHz() const;
    // What the CRTC sends to the panel, read back from the kernel: the device's writeback connector (vkms; the
    // Pi's vc4 has one, its TXP) writes the next refresh into a buffer of ours. The panel's size and orientation
    // (the frame turned by the rotation), BGR. Waits for that refresh (at most 1 s); for tests and diagnostics.
    // Throws BoothError(Device) when the device has no writeback connector, (Internal) before the first frame.
    cv::Mat readBack();

private:
    struct State;
    std::unique_ptr<State> state_;
    Rotation rotation_;
};

// Whether a DRM device with a connected screen exists (`device` empty: any /dev/dri/card*); when not, `why`
// says what is missing. Opens nothing for longer than the check.
bool kmsScreenAvailable(const std::string& device, const std::string& connector, std::string* why = nullptr);

// Whether a KMS device (`device` empty: any /dev/dri/card*) has a connector a screen can be plugged into (the one
// named, else any but writeback), connected or not: a board whose screen is off or unplugged, as opposed to a
// machine without a display controller. `what` lists them ("/dev/dri/card1 HDMI-A-1 not connected").
bool kmsScreenExpected(const std::string& device, const std::string& connector, std::string* what = nullptr);

}  // namespace avatarbooth
