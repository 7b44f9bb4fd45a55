// libcamera's log lines as our log takes them: the severity becomes spdlog's level, time and thread are dropped.
#include "drivers/camera/libcamera_log.h"

#include <gtest/gtest.h>

namespace avatarbooth {
namespace {

TEST(CameraLibcameraLog, SeverityBecomesTheLevelAndTheRestIsKept) {
    LibcameraLogLine l = parseLibcameraLogLine("[0:08:34.894301893] [1857]  INFO Camera camera_manager.cpp:293 libcamera v0.0.3");
    EXPECT_EQ(l.level, spdlog::level::info);
    EXPECT_EQ(l.text, "Camera camera_manager.cpp:293 libcamera v0.0.3");
    l = parseLibcameraLogLine("[0:08:34.949343491] [1861] ERROR CameraSensor camera_sensor.cpp:535 'ov5647 10-0036': no test pattern");
    EXPECT_EQ(l.level, spdlog::level::err);
    EXPECT_EQ(l.text, "CameraSensor camera_sensor.cpp:535 'ov5647 10-0036': no test pattern");
    EXPECT_EQ(parseLibcameraLogLine("[1:00:00.000000001] [2]  WARN V4L2 v4l2_videodevice.cpp:1 x").level, spdlog::level::warn);
    EXPECT_EQ(parseLibcameraLogLine("[1:00:00.000000001] [2] DEBUG IPC ipc.cpp:1 y").level, spdlog::level::debug);
    EXPECT_EQ(parseLibcameraLogLine("[1:00:00.000000001] [2] FATAL Camera camera.cpp:1 z").level, spdlog::level::critical);
}

TEST(CameraLibcameraLog, OtherShapesAreKeptWholeAsWarnings) {
    for (const char* line : {"Backtrace:", "", "[0:00:01.0] no thread", "[0:00:01.0] [3] LOUD Camera x"}) {
        const LibcameraLogLine l = parseLibcameraLogLine(line);
        EXPECT_EQ(l.level, spdlog::level::warn) << line;
        EXPECT_EQ(l.text, line);
    }
}

}  // namespace
}  // namespace avatarbooth
