// The display table: each backend's probe (could it show anything here) and how it opens.
#include "drivers/display/display_backends.h"

#include "drivers/display/headless_display.h"
#include "drivers/display/kms_display.h"
#include "drivers/display/window_display.h"

#include <cstdlib>

namespace avatarbooth {
namespace {

BackendProbe probeKms(const DisplaySettings& s) {
    std::string why;
    if (!kmsScreenAvailable(s.drmDevice, s.connector, &why)) return {false, why, ""};
    return {true,
            "a connected screen" + (s.drmDevice.empty() ? std::string() : " on " + s.drmDevice) +
                (s.connector.empty() ? std::string() : " at " + s.connector),
            ""};
}

BackendProbe probeWindow(const DisplaySettings&) {
    const char* x = std::getenv("DISPLAY");
    if (x == nullptr || *x == '\0') return {false, "$DISPLAY is not set", ""};
    return {true, std::string("X display ") + x, ""};
}

BackendProbe probeHeadless(const DisplaySettings& s) {
    return {true, "no screen (" + std::to_string(s.width) + "x" + std::to_string(s.height) + ")", ""};
}

std::unique_ptr<Display> openKms(const DisplaySettings& s) { return std::make_unique<KmsDisplay>(s); }
std::unique_ptr<Display> openWindow(const DisplaySettings& s) { return std::make_unique<WindowDisplay>(s); }
std::unique_ptr<Display> openHeadless(const DisplaySettings& s) { return std::make_unique<HeadlessDisplay>(s); }

constexpr DisplayBackend kDisplayBackends[] = {
    {kDisplayBackendNames[0], probeKms, openKms},
    {kDisplayBackendNames[1], probeWindow, openWindow},
    {kDisplayBackendNames[2], probeHeadless, openHeadless},
};

}  // namespace

static_assert(std::size(kDisplayBackends) == kDisplayBackendNames.size(), "a name for every row");

std::span<const DisplayBackend> displayBackends() { return kDisplayBackends; }

}  // namespace avatarbooth
