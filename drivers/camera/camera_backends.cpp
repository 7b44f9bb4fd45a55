// The camera table: each backend's probe (is there such a camera here, and which) and how it opens.
#include "drivers/camera/camera_backends.h"

#include "drivers/camera/libcamera_camera.h"
#include "drivers/camera/v4l2_camera.h"

#include <filesystem>

namespace avatarbooth {
namespace {

BackendProbe probeV4l2(const CameraSettings& s) {
    if (!s.device.empty() && !s.device.starts_with("/dev/"))
        return {false, "camera.device \"" + s.device + "\" is no /dev/ node", ""};
    if (!s.device.empty() && !std::filesystem::exists(s.device)) return {false, s.device + " not found", ""};
    const std::vector<std::string> nodes = s.device.empty() ? listV4l2Nodes() : std::vector<std::string>{s.device};
    if (nodes.empty()) return {false, "no /dev/video* node", ""};
    std::string why;
    for (const std::string& node : nodes) {
        const V4l2DeviceInfo info = probeV4l2Device(node);
        const std::string unusable = v4l2Unusable(info);
        if (unusable.empty()) return {true, "V4L2 camera " + node + " (" + info.card + ") found", node};
        why += (why.empty() ? "" : "; ") + node + ": " + unusable;
    }
    return {false, why, ""};
}

BackendProbe probeLibcamera(const CameraSettings& s) {
    if (s.device.starts_with("/dev/")) return {false, "camera.device " + s.device + " is a V4L2 node", ""};
    try {
        const std::vector<LibcameraCameraInfo> cameras = listLibcameraCameras();
        std::string ids;
        for (const LibcameraCameraInfo& c : cameras) {
            if (s.device.empty() || c.id == s.device)
                return {true, "libcamera camera " + c.id + (c.model.empty() ? "" : " (" + c.model + ")") + " found", c.id};
            ids += (ids.empty() ? "" : ", ") + c.id;
        }
        if (cameras.empty()) return {false, "no cameras found (libcamera " + libcameraVersion() + ")", ""};
        return {false, "no camera " + s.device + " (found: " + ids + ")", ""};
    } catch (const BoothError& e) {
        return {false, e.what(), ""};
    }
}

BackendProbe probeSim(const CameraSettings& s) {
    return {true, "the simulated camera (" + (s.simFolder.empty() ? std::string("the synthetic visitor") : s.simFolder) + ")", ""};
}

std::unique_ptr<Camera> openV4l2(const CameraSettings& s, const CameraEnvironment&) { return std::make_unique<V4l2Camera>(s); }

std::unique_ptr<Camera> openLibcamera(const CameraSettings& s, const CameraEnvironment&) {
    return std::make_unique<LibcameraCamera>(s);
}

std::unique_ptr<Camera> openSim(const CameraSettings& s, const CameraEnvironment& env) {
    SimCameraOptions options;
    options.folder = s.simFolder;
    options.fps = s.simFps;
    options.previewWidth = s.previewWidth;
    options.previewHeight = s.previewHeight;
    options.noise = s.simNoise;
    return std::make_unique<SimCamera>(options, env.simControls, env.clock);
}

constexpr CameraBackend kCameraBackends[] = {
    {kCameraBackendNames[0], probeV4l2, openV4l2},
    {kCameraBackendNames[1], probeLibcamera, openLibcamera},
    {kCameraBackendNames[2], probeSim, openSim},
};

}  // namespace

static_assert(std::size(kCameraBackends) == kCameraBackendNames.size(), "a name for every row");

std::span<const CameraBackend> cameraBackends() { return kCameraBackends; }

}  // namespace avatarbooth
