// The camera factory: the backend choice through the camera table, opening it behind reopening, and the
// machine's camera list.
#include "drivers/camera/camera_factory.h"

#include "drivers/camera/libcamera_camera.h"
#include "drivers/camera/v4l2_camera.h"

#include <spdlog/spdlog.h>

#include <cmath>

namespace avatarbooth {

namespace {

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

CameraEnvironment completed(const CameraSettings& s, CameraEnvironment env) {
    if (!env.simControls) env.simControls = std::make_shared<SimCameraControls>();
    if (!env.clock) {
        if (s.backend == "sim" && !s.simRealTime)
            env.clock = std::make_shared<ManualClock>(SteadyTime{});
        else
            env.clock = std::make_shared<SteadyClock>();
    }
    return env;
}

std::chrono::nanoseconds seconds(double s) {
    return std::chrono::nanoseconds(static_cast<long long>(std::llround(std::max(0.0, s) * 1e9)));
}

}  // namespace

CameraBackendChoice chooseCameraBackend(const CameraSettings& s) {
    const std::span<const CameraBackend> table = cameraBackends();
    if (s.backend != "auto") {
        const CameraBackend* entry = findBackend(table, s.backend);
        if (!entry)
            throw BoothError(ErrorKind::BadConfig, "camera.backend",
                             "unknown camera backend \"" + s.backend + "\" (" + backendWordList(table) + ")");
        const bool sim = s.backend == "sim";
        return {entry, s.backend, sim ? s.simFolder : s.device, s.backend + " (configured)", false, ""};
    }
    const BackendChoice<CameraBackend> choice = probeBackends(table, s);
    // The table ends with the sim camera, which is always usable.
    const std::string name(choice.backend->name);
    std::string reason = "auto: " + choice.probe.text;
    if (name == "sim") {
        const std::string looked = s.device.empty() ? "no V4L2 or libcamera camera found" : "camera " + s.device + " not found";
        reason = "auto: " + looked + ", using the simulated camera";
    }
    return {choice.backend, name, name == "sim" ? s.simFolder : choice.probe.device, reason, true, passedOver(choice.passed)};
}

std::string cameraChoiceLog(const CameraBackendChoice& choice) {
    return choice.reason + (choice.passedOver.empty() ? "" : " (" + choice.passedOver + ")");
}

CameraSettings resolvedCameraSettings(const CameraSettings& settings, const CameraBackendChoice& choice) {
    CameraSettings resolved = settings;
    resolved.backend = choice.backend;
    if (choice.backend != "sim") resolved.device = choice.device;
    return resolved;
}

std::unique_ptr<ReopeningCamera> openReopeningCamera(const CameraSettings& settings, CameraEnvironment environment) {
    const CameraBackendChoice choice = chooseCameraBackend(settings);
    const CameraSettings resolved = resolvedCameraSettings(settings, choice);
    const CameraEnvironment env = completed(resolved, std::move(environment));
    if (choice.automatic) spdlog::info("camera: {}", cameraChoiceLog(choice));
    const std::string note = choice.automatic ? choice.reason : std::string();
    auto opener = [openBackend = choice.entry->open, resolved, env, note]() -> std::unique_ptr<Camera> {
        auto camera = openBackend(resolved, env);
        if (note.empty()) return camera;
        return std::make_unique<ChosenCamera>(std::move(camera), note);
    };
    const std::string label = choice.backend == "sim" ? "sim:" + choice.device
                              : choice.device.empty() ? choice.backend : choice.device;
    const ReopenPolicy policy{seconds(settings.reopenFirstDelaySeconds), seconds(settings.reopenMaxDelaySeconds)};
    return std::make_unique<ReopeningCamera>(opener, label, policy, env.clock);
}

std::vector<CameraListEntry> listCameras() {
    std::vector<CameraListEntry> list;
    for (const auto& node : listV4l2Nodes()) {
        const auto info = probeV4l2Device(node);
        CameraListEntry e;
        e.backend = "v4l2";
        e.device = node;
        e.name = info.card.empty() ? "" : info.card + " [" + info.driver + ", " + info.bus + "]";
        e.usable = v4l2Unusable(info).empty();
        if (!info.error.empty() || !info.canCapture)
            e.formats = v4l2Unusable(info);
        else
            e.formats = (info.mediaControllerCentric ? "media-controller node (use libcamera): " : "") +
                        describeV4l2Formats(info.formats);
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
