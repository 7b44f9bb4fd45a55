// The camera interface the booth sees: a preview stream of BGR frames and full-resolution stills, whatever the
// backend (V4L2, libcamera, the simulated camera).
#pragma once

#include "common/error.h"

#include <opencv2/core.hpp>

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

namespace avatarbooth {

// One picture from a camera.
struct CameraFrame {
    cv::Mat image;  // 8-bit BGR, owned by the frame (never a view into a driver buffer)
    // Preview frames: counts up from 0 over the life of the camera object; a gap means frames were dropped.
    // Stills: the number of stills taken before this one.
    std::uint64_t sequence = 0;
    // When the frame was exposed, on CLOCK_MONOTONIC (std::chrono::steady_clock on Linux) for every backend, so
    // it can be compared with the booth's own clock. The simulated camera uses its injected clock instead.
    std::chrono::nanoseconds timestamp{0};
};

// A stream configuration as the device accepted it.
struct CameraStreamFormat {
    std::string pixelFormat;  // the device's format name, e.g. "YUYV", "MJPG", "RGB888", "sim"
    int width = 0;
    int height = 0;
    double fps = 0;  // the nominal rate; 0 when the device does not say
};

struct CameraDescription {
    std::string backend;  // "v4l2", "libcamera" or "sim"
    std::string device;   // the device node, the libcamera camera id, or the sim folder
    std::string name;     // what the device calls itself (V4L2 card, libcamera model), or "simulated camera"
    CameraStreamFormat preview;
    CameraStreamFormat still;
    std::string note;     // why this backend was chosen (set by openReopeningCamera for "auto"), or empty

    // One line for logs and the operator screen, e.g.
    // "v4l2 /dev/video0 (HD Webcam): preview YUYV 1280x720 @30 fps, still MJPG 1920x1080".
    std::string summary() const;
};

// The camera went away while in use (unplugged, powered off, ENODEV/EIO from the driver). Distinct from other
// device errors so that a ReopeningCamera can tell "reopen and carry on" from "misconfigured". The message reads
// "camera /dev/video0 disconnected (...)".
class CameraGoneError : public BoothError {
public:
    CameraGoneError(const std::string& device, const std::string& detail)
        : BoothError(ErrorKind::Device, "", "camera " + device + " disconnected" + (detail.empty() ? "" : " (" + detail + ")")),
          device_(device) {}
    const std::string& device() const { return device_; }

private:
    std::string device_;
};

// A camera opened by its constructor (which throws BoothError(Device) naming the device when it cannot be
// opened) and closed by its destructor. Not thread-safe: one thread drives it.
class Camera {
public:
    virtual ~Camera() = default;

    // Starts the preview stream (a no-op when it runs).
    virtual void start() = 0;
    // Waits up to `timeout` for the next preview frame; nullopt when none came in time. Starts the stream if it
    // is not running. Frames the driver marks as broken are skipped (a gap in the sequence numbers).
    virtual std::optional<CameraFrame> nextFrame(std::chrono::milliseconds timeout) = 0;
    // Takes one picture at the still resolution. When that differs from the preview's, the stream is stopped,
    // switched to the still format for one frame and switched back (and restarted if it was running).
    virtual CameraFrame captureStill() = 0;
    // Stops the preview stream (a no-op when it is stopped).
    virtual void stop() = 0;
    // Backend, device and the formats in use.
    virtual CameraDescription describe() const = 0;
};

}  // namespace avatarbooth
