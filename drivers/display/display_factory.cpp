// Display selection: kms, window, headless, or the first that works.
#include "drivers/display/display_factory.h"

#include "common/error.h"
#include "drivers/display/headless_display.h"
#include "drivers/display/kms_display.h"
#include "drivers/display/window_display.h"

#include <cstdlib>

namespace avatarbooth {

OpenedDisplay createDisplay(const DisplaySettings& settings) {
    rotationFromDegrees(settings.rotation);  // a bad rotation is a config error whichever backend is chosen
    OpenedDisplay out;
    const std::string& b = settings.backend;
    if (b == "kms") out.display = std::make_unique<KmsDisplay>(settings);
    else if (b == "window") out.display = std::make_unique<WindowDisplay>(settings);
    else if (b == "headless") out.display = std::make_unique<HeadlessDisplay>(settings);
    if (out.display) {
        out.description = "display: " + out.display->describe();
        return out;
    }
    if (b != "auto")
        throw BoothError(ErrorKind::BadConfig, "display.backend",
                         "\"" + b + "\" is not a display (auto, kms, window or headless)");

    std::string passed;
    std::string why;
    if (kmsScreenAvailable(settings.drmDevice, settings.connector, &why)) {
        try {
            out.display = std::make_unique<KmsDisplay>(settings);
        } catch (const BoothError& e) {
            why = e.what();
        }
    }
    if (!out.display) {
        passed = "kms: " + why;
        const char* x = std::getenv("DISPLAY");
        if (x != nullptr && *x != '\0') {
            try {
                out.display = std::make_unique<WindowDisplay>(settings);
            } catch (const BoothError& e) {
                passed += "; window: " + std::string(e.what());
            }
        } else {
            passed += "; window: $DISPLAY is not set";
        }
    }
    if (!out.display) out.display = std::make_unique<HeadlessDisplay>(settings);
    out.description = "display: " + out.display->describe() + " (auto" + (passed.empty() ? "" : ": " + passed) + ")";
    return out;
}

}  // namespace avatarbooth
