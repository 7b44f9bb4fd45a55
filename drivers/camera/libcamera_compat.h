// Where libcamera's API differs between the releases the booth builds against: Debian bookworm's 0.0.3 and trixie's
// 0.4 (Raspberry Pi OS trixie ships Raspberry Pi's 0.5). Every version test of the libcamera backend is in this
// file, keyed on <libcamera/version.h>; libcamera_camera.cpp uses only API that all of them share otherwise.
//
// What moved, and what the backend avoids rather than wraps:
// - 0.2 replaced CameraConfiguration::transform (a Transform applied after the pipeline's own fix-up of the sensor's
//   mounting rotation) with ::orientation (the images' orientation, the mounting rotation folded in). Identity and
//   Rotate0 both mean upright images; uprightImages() asks each release for them in its own words.
// - 0.1 removed CameraManager::get(dev_t) (the backend looks cameras up by id); 0.5 removed controls::AeLocked
//   (unused: the booth takes a still after stillWarmupFrames, see camera_settings.h).
// - generateConfiguration() takes a Span of roles since 0.1; a braced list of roles works on both.
#pragma once

#include <libcamera/camera.h>
#include <libcamera/version.h>

#include <sstream>
#include <string>

#define AVATARBOOTH_LIBCAMERA_AT_LEAST(major, minor) \
    (LIBCAMERA_VERSION_MAJOR > (major) || (LIBCAMERA_VERSION_MAJOR == (major) && LIBCAMERA_VERSION_MINOR >= (minor)))

#if AVATARBOOTH_LIBCAMERA_AT_LEAST(0, 2)
#include <libcamera/orientation.h>
#else
#include <libcamera/transform.h>
#endif

namespace avatarbooth::libcamera_compat {

// Asks for images the right way up whatever way the sensor is mounted (its Rotation property: 180 on a module
// fitted upside down). validate() adjusts the request when the pipeline cannot rotate; orientationName() then says
// what the camera gives.
inline void uprightImages(libcamera::CameraConfiguration& config) {
#if AVATARBOOTH_LIBCAMERA_AT_LEAST(0, 2)
    config.orientation = libcamera::Orientation::Rotate0;
#else
    config.transform = libcamera::Transform::Identity;
#endif
}

// The orientation `config` has (after validate()), for logs: "Rotate0" (0.2+) or "identity" (0.0.3) when the
// images come upright, else what the camera does instead.
inline std::string orientationName(const libcamera::CameraConfiguration& config) {
#if AVATARBOOTH_LIBCAMERA_AT_LEAST(0, 2)
    std::ostringstream out;
    out << config.orientation;
    return out.str();
#else
    return libcamera::transformToString(config.transform);
#endif
}

}  // namespace avatarbooth::libcamera_compat
