// The camera factory: backend choice, construction, and the machine's camera list.
#include "drivers/camera/camera_factory.h"

#include "drivers/camera/libcamera_camera.h"
#include "drivers/camera/v4l2_camera.h"

#include <spdlog/spdlog.h>

#include <cmath>

namespace avatarbooth {

namespace {

// A node the v4l2 backend can stream from on its own: a capture node with a format we read, not one end of a
// media-controller pipeline (those are libcamera's).
bool usableV4l2(const V4l2DeviceInfo& info) {
    return info.canCapture && !info.mediaControllerCentric && negotiateV4l2Format(info.formats, 0, 0, 0).has_value();
}

// Adds the reason for the choice to the description; everything else goes straight through.
class ChosenCamera : public Camera {
public:
    ChosenCamera(std::unique_ptr<Camera> camera, std::string note) : camera_(std::move(camera)), note_(std::move(note)) {}
    void start() override { camera_->start(); }
    std::optional<CameraFrame> nextFrame(std::chrono::milliseconds timeout) override { return camera_->nextFrame(timeout); }
    CameraFrame captureStill() override { return camera_->captureStill(); }
    void stop() override { camera_->stop(); }
    CameraDescription describe() const override {
        auto d = camera_->describe();
        d.note = note_;
        return d;
    }

private:
    std::unique_ptr<Camera> camera_;
    std::string note_;
};

std::unique_ptr<Camera> openBackend(const CameraSettings& s, const CameraEnvironment& env) {
    if (s.backend == "v4l2") return std::make_unique<V4l2Camera>(s);
    if (s.backend == "libcamera") return std::make_unique<LibcameraCamera>(s);
    if (s.backend == "sim") {
        SimCameraOptions options;
        options.folder = s.simFolder;
        options.fps = s.simFps;
        options.previewWidth = s.previewWidth;
        options.previewHeight = s.previewHeight;
        options.noise = s.simNoise;
        return std::make_unique<SimCamera>(options, env.simControls, env.clock);
    }
    throw BoothError(ErrorKind::BadConfig, "camera.backend",
                     "unknown camera backend \"" + s.backend + "\" (auto, v4l2, libcamera or sim)");
}

CameraEnvironment completed(const CameraSettings& s, CameraEnvironment env) {
    if (!env.simControls) env.simControls = std::make_shared<SimCameraControls>();
    if (!env.clock) {
        if (s.backend == "sim" && !s.simRealTime)
            env.clock = std::make_shared<ManualCameraClock>();
        else
            env.clock = std::make_shared<SteadyCameraClock>();
    }
    return env;
}

std::chrono::nanoseconds seconds(double s) {
    return std::chrono::nanoseconds(static_cast<long long>(std::llround(std::max(0.0, s) * 1e9)));
}

}  // namespace

CameraBackendChoice chooseCameraBackend(const CameraSettings& s) {
    if (s.backend == "v4l2" || s.backend == "libcamera") return {s.backend, s.device, s.backend + " (configured)"};
    if (s.backend == "sim") return {"sim", s.simFolder, "sim (configured)"};
    if (s.backend != "auto")
        throw BoothError(ErrorKind::BadConfig, "camera.backend",
                         "unknown camera backend \"" + s.backend + "\" (auto, v4l2, libcamera or sim)");

    const bool deviceIsNode = s.device.starts_with("/dev/");
    std::vector<std::string> nodes = deviceIsNode ? std::vector<std::string>{s.device} : listV4l2Nodes();
    if (s.device.empty() || deviceIsNode) {
        for (const auto& node : nodes) {
            const auto info = probeV4l2Device(node);
            if (usableV4l2(info))
                return {"v4l2", node, "auto: V4L2 camera " + node + " (" + info.card + ") found"};
        }
    }
    if (!deviceIsNode) {
        try {
            const auto cameras = listLibcameraCameras();
            for (const auto& c : cameras)
                if (s.device.empty() || c.id == s.device)
                    return {"libcamera", c.id, "auto: libcamera camera " + c.id + (c.model.empty() ? "" : " (" + c.model + ")") + " found"};
        } catch (const BoothError& e) {
            spdlog::debug("camera auto: libcamera unavailable: {}", e.what());
        }
    }
    const std::string looked = s.device.empty() ? "no V4L2 or libcamera camera found" : "camera " + s.device + " not found";
    return {"sim", s.simFolder, "auto: " + looked + ", using the simulated camera"};
}

std::unique_ptr<Camera> openCamera(const CameraSettings& settings, CameraEnvironment environment) {
    const auto choice = chooseCameraBackend(settings);
    auto resolved = settings;
    resolved.backend = choice.backend;
    if (choice.backend != "sim") resolved.device = choice.device;
    const auto env = completed(resolved, std::move(environment));
    auto camera = openBackend(resolved, env);
    if (settings.backend != "auto") return camera;
    spdlog::info("camera: {}", choice.reason);
    return std::make_unique<ChosenCamera>(std::move(camera), choice.reason);
}

std::unique_ptr<ReopeningCamera> openReopeningCamera(const CameraSettings& settings, CameraEnvironment environment) {
    const auto choice = chooseCameraBackend(settings);
    auto resolved = settings;
    resolved.backend = choice.backend;
    if (choice.backend != "sim") resolved.device = choice.device;
    const auto env = completed(resolved, std::move(environment));
    if (settings.backend == "auto") spdlog::info("camera: {}", choice.reason);
    const std::string note = settings.backend == "auto" ? choice.reason : std::string();
    auto open = [resolved, env, note]() -> std::unique_ptr<Camera> {
        auto camera = openBackend(resolved, env);
        if (note.empty()) return camera;
        return std::make_unique<ChosenCamera>(std::move(camera), note);
    };
    const std::string label = choice.backend == "sim" ? "sim:" + choice.device
                              : choice.device.empty() ? choice.backend : choice.device;
    const ReopenPolicy policy{seconds(settings.reopenFirstDelaySeconds), seconds(settings.reopenMaxDelaySeconds)};
    return std::make_unique<ReopeningCamera>(open, label, policy, env.clock);
}

std::vector<CameraListEntry> listCameras() {
    std::vector<CameraListEntry> list;
    for (const auto& node : listV4l2Nodes()) {
        const auto info = probeV4l2Device(node);
        CameraListEntry e;
        e.backend = "v4l2";
        e.device = node;
        e.name = info.card.empty() ? "" : info.card + " [" + info.driver + ", " + info.bus + "]";
        if (!info.error.empty())
            e.formats = info.error;
        else if (!info.canCapture)
            e.formats = "not a single-planar video capture node";
        else
            e.formats = (info.mediaControllerCentric ? "media-controller node (use libcamera): " : "") +
                        describeV4l2Formats(info.formats);
        e.usable = usableV4l2(info);
        list.push_back(std::move(e));
    }
    try {
        for (const auto& c : listLibcameraCameras()) list.push_back({"libcamera", c.id, c.model, "", true});
    } catch (const std::exception& e) {
        list.push_back({"libcamera", "", "", e.what(), false});
    }
    return list;
}

}  // namespace avatarbooth
