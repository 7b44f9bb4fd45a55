// Opening the camera the settings ask for ("auto" takes the first backend of the camera table that finds a
// camera: a real one when present, else the simulated one), and listing the cameras on this machine for
// `avatarbooth check`.
#pragma once

#include "drivers/camera/camera.h"
#include "drivers/camera/camera_backends.h"
#include "drivers/camera/camera_settings.h"
#include "drivers/camera/reopening_camera.h"

#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

struct CameraBackendChoice {
    const CameraBackend* entry = nullptr;  // its row in cameraBackends()
    std::string backend;  // "v4l2", "libcamera" or "sim"
    std::string device;   // the device node / camera id / sim folder it will open
    std::string reason;   // e.g. "auto: no V4L2 or libcamera camera found, using the simulated camera"
    bool automatic = false;  // chosen by "auto" (else configured by name, and not probed)
    std::string passedOver;  // auto: why the earlier backends were passed over ("v4l2: ...; libcamera: ..."), or ""
};

// Resolves settings.backend: "auto" walks cameraBackends() in order and takes the first whose probe finds a
// camera; a name is looked up in the same table and taken as it is. Throws BoothError(BadConfig) for an unknown
// backend name.
CameraBackendChoice chooseCameraBackend(const CameraSettings& settings);

// The choice for the start-up log: the reason and, for "auto", why the earlier backends were passed over.
std::string cameraChoiceLog(const CameraBackendChoice& choice);

// The settings with the choice made: the backend named, and the device it found (so opening them again probes
// nothing and opens the same camera).
CameraSettings resolvedCameraSettings(const CameraSettings& settings, const CameraBackendChoice& choice);

// Opens the camera (not yet streaming), wrapped so that it is reopened with back-off when it goes away; the one
// way to open a camera. "auto" is resolved once, so a lost USB camera is waited for rather than replaced by the
// simulated one; the choice and its reason are logged and put in describe().note. A missing device is not thrown
// (the camera starts out lost and says why in status()); a bad configuration or sim folder is.
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
