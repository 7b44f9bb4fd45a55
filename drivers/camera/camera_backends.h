// The camera backends as one table, in the order "auto" tries them: V4L2, libcamera, the simulated camera.
#pragma once

#include "common/backend_table.h"
#include "drivers/camera/camera.h"
#include "common/clock.h"
#include "drivers/camera/camera_settings.h"
#include "drivers/camera/sim_camera.h"

#include <memory>
#include <array>
#include <span>
#include <string_view>

namespace avatarbooth {

// What the cameras share with the rest of the booth.
struct CameraEnvironment {
    // The simulated world (scene, faults) the sim camera reads; one is made when null. Keep it to drive the
    // simulation: a reopened sim camera reads the same one.
    std::shared_ptr<SimCameraControls> simControls;
    // The clock of the sim camera and of reopen back-off; null: the steady clock, or for a sim camera with
    // simRealTime = false a manual clock starting at 0 (frames as fast as asked).
    std::shared_ptr<Clock> clock;
};

// Opens the backend's camera (not yet streaming) on settings.device, with an environment whose controls and clock
// are set. Throws what the backend throws (BoothError Device for a missing device, naming it).
using OpenCamera = std::unique_ptr<Camera> (*)(const CameraSettings& settings, const CameraEnvironment& environment);
using CameraBackend = Backend<CameraSettings, OpenCamera>;

// v4l2 (a node offering a format we read; settings.device a /dev/ name or ""), libcamera (settings.device a camera
// id or ""), sim (always usable). The probes look without streaming and never throw.
// The table's names in its order: the words the configuration accepts after "auto" (read without the table, so
// that the configuration needs none of the drivers).
inline constexpr std::array<std::string_view, 3> kCameraBackendNames{"v4l2", "libcamera", "sim"};
std::span<const CameraBackend> cameraBackends();

}  // namespace avatarbooth
