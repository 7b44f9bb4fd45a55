// Choosing the display by name: "auto", "kms", "window" or "headless".
#pragma once

#include "drivers/display/display.h"
#include "drivers/display/display_settings.h"

#include <memory>
#include <string>

namespace avatarbooth {

struct OpenedDisplay {
    std::unique_ptr<Display> display;
    // Which backend and why, for the start-up log: "display: headless 1280x720 (auto: no DRM device ...;
    // $DISPLAY is not set)".
    std::string description;
};

// Opens settings.backend. "auto" tries kms when a DRM device has a connected screen, then window when $DISPLAY
// is set, then headless, and says why each earlier one was passed over (a failure to open is reported, not
// thrown). A named backend that cannot open throws its BoothError(Device); an unknown name is BadConfig.
OpenedDisplay createDisplay(const DisplaySettings& settings);

}  // namespace avatarbooth
