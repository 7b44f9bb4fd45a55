// The V4L2 backend: a USB (UVC) or other single-planar capture device through the kernel's ioctls, mmap
// streaming, YUYV/MJPEG (and RGB24/BGR24) converted to BGR.
#pragma once

#include "drivers/camera/camera.h"
#include "drivers/camera/camera_settings.h"
#include "drivers/camera/format_negotiation.h"

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace avatarbooth {

// What a V4L2 node is, as `avatarbooth check` lists it.
struct V4l2DeviceInfo {
    std::string path;
    std::string card;    // the device's name
    std::string driver;  // e.g. "uvcvideo", "vivid"
    std::string bus;     // e.g. "usb-0000:01:00.0-1.3"
    bool canCapture = false;  // single-planar video capture with streaming (what this backend drives)
    // The node is one end of a media-controller pipeline (V4L2_CAP_IO_MC: a Pi's unicam, vimc, ISPs); it streams
    // only once the pipeline is configured, which libcamera does: "auto" leaves such nodes to libcamera.
    bool mediaControllerCentric = false;
    std::vector<V4l2Format> formats;
    std::string error;   // why it could not be opened or queried; empty when it could
};

// Opens and queries a node without streaming; never throws (errors land in `error`).
V4l2DeviceInfo probeV4l2Device(const std::string& path);
// Why the v4l2 backend cannot stream from the node on its own, "" when it can: the node is a capture node with a
// format we read, not one end of a media-controller pipeline (those are libcamera's).
std::string v4l2Unusable(const V4l2DeviceInfo& info);
// The /dev/video* nodes in numeric order.
std::vector<std::string> listV4l2Nodes();

class V4l2Camera : public Camera {
public:
    // Opens settings.device, checks it is a capture device with streaming, reads its formats and chooses the
    // preview and still formats. Throws BoothError(Device) naming the device: missing ("no such camera
    // device"), not permitted, busy, not a capture device, or no format we can read (with the formats it has).
    explicit V4l2Camera(const CameraSettings& settings);
    ~V4l2Camera() override;
    V4l2Camera(const V4l2Camera&) = delete;
    V4l2Camera& operator=(const V4l2Camera&) = delete;

    void start() override;
    std::optional<CameraFrame> nextFrame(std::chrono::milliseconds timeout) override;
    CameraFrame captureStill() override;
    void stop() override;
    CameraDescription describe() const override;

    const std::vector<V4l2Format>& formats() const { return formats_; }
    // Frames the driver flagged as broken or that did not convert, since opening.
    std::uint64_t droppedFrames() const { return dropped_; }

private:
    struct Mapped {
        void* start = nullptr;
        std::size_t length = 0;
    };
    // The format the device is set to.
    struct Active {
        std::uint32_t fourcc = 0;
        int width = 0, height = 0;
        std::size_t bytesPerLine = 0;
        double fps = 0;
    };

    [[noreturn]] void fail(const char* call, int error) const;
    void setFormat(const V4l2FormatChoice& choice, double fps);
    void startStreaming(int bufferCount);
    void stopStreaming() noexcept;
    std::optional<CameraFrame> readFrame(std::chrono::milliseconds timeout);
    bool activeIs(const V4l2FormatChoice& choice) const;

    CameraSettings settings_;
    std::string device_;
    int fd_ = -1;
    std::string card_;
    std::vector<V4l2Format> formats_;
    V4l2FormatChoice previewChoice_, stillChoice_;
    Active active_;
    Active previewActive_, stillActive_;  // as the device accepted them (still: once one was taken)
    std::vector<Mapped> buffers_;
    bool streaming_ = false;      // the device streams (preview or still)
    bool previewRunning_ = false; // the preview stream is wanted and running
    std::uint64_t sequenceBase_ = 0, nextSequence_ = 0, stillsTaken_ = 0, dropped_ = 0;
};

}  // namespace avatarbooth
