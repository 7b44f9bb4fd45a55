// The vivid capture node the kernel tests open (the node numbers depend on what else the guest has loaded).
#pragma once

#include "drivers/camera/v4l2_camera.h"

#include <string>

namespace avatarbooth::kernel_test {

// The first node whose driver is vivid and which can capture, or "" when there is none.
inline std::string vividNode() {
    for (const auto& node : listV4l2Nodes()) {
        const V4l2DeviceInfo info = probeV4l2Device(node);
        if (info.driver == "vivid" && info.canCapture) return node;
    }
    return "";
}

}  // namespace avatarbooth::kernel_test
