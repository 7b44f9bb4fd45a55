// The libcamera backend (Raspberry Pi CSI cameras, and UVC cameras through libcamera): a viewfinder stream for
// the preview and a still-capture configuration for photos. libcamera types stay out of this header.
//
// Builds against Debian bookworm's libcamera 0.0.3 and trixie's 0.4 (Raspberry Pi OS trixie: 0.5); what differs
// between them is in libcamera_compat.h, the rest is API all of them keep.
#pragma once

#include "drivers/camera/camera.h"
#include "drivers/camera/camera_settings.h"

#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

struct LibcameraCameraInfo {
    std::string id;     // what CameraSettings::device takes
    std::string model;  // the sensor's name, when the pipeline says
};

// The cameras libcamera sees, and libcamera's version. Throws BoothError(Device) when libcamera's camera manager
// does not start.
std::vector<LibcameraCameraInfo> listLibcameraCameras();
std::string libcameraVersion();

class LibcameraCamera : public Camera {
public:
    // Picks settings.device (a camera id; "" = the first camera), acquires it and validates the viewfinder and
    // still configurations. Throws BoothError(Device): "no cameras found", no camera with that id (listing
    // those there are), the camera in use, or no configuration with a pixel format we convert.
    explicit LibcameraCamera(const CameraSettings& settings);
    ~LibcameraCamera() override;
    LibcameraCamera(const LibcameraCamera&) = delete;
    LibcameraCamera& operator=(const LibcameraCamera&) = delete;

    void start() override;
    std::optional<CameraFrame> nextFrame(std::chrono::milliseconds timeout) override;
    CameraFrame captureStill() override;
    void stop() override;
    CameraDescription describe() const override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace avatarbooth
