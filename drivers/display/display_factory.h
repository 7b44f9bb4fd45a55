// Opening the display the settings name, or for "auto" the first of the display table (display_backends.h) that
// works.
#pragma once

#include "drivers/display/display.h"
#include "drivers/display/display_settings.h"
#include "drivers/display/reopening_display.h"

#include <memory>
#include <string>

namespace avatarbooth {

struct OpenedDisplay {
    std::unique_ptr<Display> display;
    // Which backend and why, for the start-up log: "display: headless 1280x720 (auto: kms: no DRM device ...;
    // window: $DISPLAY is not set)".
    std::string description;
    // The KMS screen's reopening wrapper (the same object as `display`), for its status; null for the other
    // backends, which have no screen to lose.
    ReopeningDisplay* reopening = nullptr;
};

// Opens settings.backend. "auto" walks displayBackends() (kms when a DRM device has a connected screen, then window
// when $DISPLAY is set, then headless) and says why each earlier one was passed over (a failure to open is
// reported and passed over too, not thrown). A named backend that cannot open throws its BoothError(Device); a
// name the table does not have is BadConfig.
//
// kms is always opened through a ReopeningDisplay: a screen switched off or unplugged later is waited for, not
// fatal. And where a KMS device has a connector but no screen is connected now (a board whose monitor is off),
// both "kms" and "auto" (when no window is possible either) start without a screen and wait for one, instead of
// failing ("kms") or running headless for good ("auto"): see displayWaitsForScreen.
OpenedDisplay createDisplay(const DisplaySettings& settings);

// Whether createDisplay would start the KMS screen lost and wait for it: the settings name "kms" or "auto", no
// screen is connected now, "auto" has no X display to fall back on either, and a KMS device has a connector for a
// screen (kmsScreenExpected). `what` lists the connectors. Machines without a DRM device (CI, most development
// machines) are not waited on: "auto" runs headless there.
bool displayWaitsForScreen(const DisplaySettings& settings, std::string* what = nullptr);

}  // namespace avatarbooth
