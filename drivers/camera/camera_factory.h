// Opening the camera the settings ask for ("auto" picks a real one when present, else the simulated one), and
// listing the cameras on this machine for `avatarbooth check`.
#pragma once

#include "drivers/camera/camera.h"
#include "drivers/camera/camera_clock.h"
#include "drivers/camera/camera_settings.h"
#include "drivers/camera/reopening_camera.h"
#include "drivers/camera/sim_camera.h"

#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

// What the cameras share with the rest of the booth.
struct CameraEnvironment {
    // The simulated world (scene, faults) the sim camera reads; one is made when null. Keep it to drive the
    // simulation: a reopened sim camera reads the same one.
    std::shared_ptr<SimCameraControls> simControls;
    // The clock of the sim camera and of reopen back-off; null: the steady clock, or for a sim camera with
    // simRealTime = false a manual clock starting at 0 (frames as fast as asked).
    std::shared_ptr<CameraClock> clock;
};

struct CameraBackendChoice {
    std::string backend;  // "v4l2", "libcamera" or "sim"
    std::string device;   // the device node / camera id / sim folder it will open
    std::string reason;   // e.g. "auto: no V4L2 or libcamera camera found, using the simulated camera"
};

// Resolves settings.backend ("auto" probes V4L2 nodes, then libcamera; an explicit backend is taken as it is).
// Throws BoothError(BadConfig) for an unknown backend name.
CameraBackendChoice chooseCameraBackend(const CameraSettings& settings);

// Opens the camera (not yet streaming). For "auto" the choice and its reason are logged and put in
// describe().note. Throws what the backend throws (BoothError Device for a missing device, naming it).
std::unique_ptr<Camera> openCamera(const CameraSettings& settings, CameraEnvironment environment = {});

// The same camera wrapped so that it is reopened with back-off when it goes away. "auto" is resolved once, so
// a lost USB camera is waited for rather than replaced by the simulated one.
std::unique_ptr<ReopeningCamera> openReopeningCamera(const CameraSettings& settings, CameraEnvironment environment = {});

struct CameraListEntry {
    std::string backend;  // "v4l2" or "libcamera"
    std::string device;   // node or camera id
    std::string name;     // card / model, with the V4L2 driver and bus
    std::string formats;  // what it offers, or why it could not be asked
    bool usable = false;  // the booth can stream from it with this backend
};

// Every V4L2 node (/dev/video*) with its formats, then every libcamera camera. Never throws: failures are
// entries with usable = false.
std::vector<CameraListEntry> listCameras();

}  // namespace avatarbooth
