// libcamera's own log routed into ours (spdlog, so the journal), without terminal colours: its warnings and errors
// are kept, its INFO chatter ("libcamera v0.0.3" at every camera manager start) is not.
#pragma once

#include <spdlog/common.h>

#include <string>
#include <string_view>

namespace avatarbooth {

struct LibcameraLogLine {
    spdlog::level::level_enum level = spdlog::level::warn;
    std::string text;  // "Camera camera_manager.cpp:299 libcamera v0.0.3": category, source, message
};

// One line as libcamera writes it to a stream, "[0:08:34.894301893] [1857]  WARN Camera camera.cpp:293 message":
// its severity as spdlog's level, and what follows it (libcamera's time and thread id are dropped: spdlog stamps
// its own). A line of another shape is kept whole at warning level.
LibcameraLogLine parseLibcameraLogLine(std::string_view line);

// From now on libcamera logs into spdlog: WARN and above as spdlog warnings (ERROR, FATAL as errors), lower ones
// dropped unless LIBCAMERA_LOG_LEVELS asks libcamera for them (then at spdlog's info and debug, seen with -v).
// With LIBCAMERA_LOG_FILE set libcamera's log stays where that sends it. Call before the first CameraManager;
// repeated calls do nothing.
void routeLibcameraLogToSpdlog();

}  // namespace avatarbooth
