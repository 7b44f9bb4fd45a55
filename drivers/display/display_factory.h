// Opening the display the settings name, or for "auto" the first of the display table (display_backends.h) that
// works.
#pragma once

#include "drivers/display/display.h"
#include "drivers/display/display_settings.h"

#include <memory>
#include <string>

namespace avatarbooth {

struct OpenedDisplay {
    std::unique_ptr<Display> display;
    // Which backend and why, for the start-up log: "display: headless 1280x720 (auto: kms: no DRM device ...;
    // window: $DISPLAY is not set)".
    std::string description;
};

// Opens settings.backend. "auto" walks displayBackends() (kms when a DRM device has a connected screen, then window
// when $DISPLAY is set, then headless) and says why each earlier one was passed over (a failure to open is
// reported and passed over too, not thrown). A named backend that cannot open throws its BoothError(Device); a
// name the table does not have is BadConfig.
OpenedDisplay createDisplay(const DisplaySettings& settings);

}  // namespace avatarbooth
