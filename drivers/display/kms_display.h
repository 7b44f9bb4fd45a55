// The kiosk's screen: EGL + OpenGL ES on a GBM surface, shown with KMS page flips (no X, no Wayland).
#pragma once

#include "drivers/display/display.h"
#include "drivers/display/display_settings.h"

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
    // for the flip, so frames are paced by the screen's refresh.
    void present(const cv::Mat& bgr) override;
    cv::Size size() const override;
    Rotation rotation() const override { return rotation_; }
    std::string describe() const override;

private:
    struct State;
    std::unique_ptr<State> state_;
    Rotation rotation_;
};

// Whether a DRM device with a connected screen exists (`device` empty: any /dev/dri/card*); when not, `why`
// says what is missing. Opens nothing for longer than the check.
bool kmsScreenAvailable(const std::string& device, const std::string& connector, std::string* why = nullptr);

}  // namespace avatarbooth
