// Display selection through the display table: a backend by name, or the first that works; the KMS screen behind
// its reopening wrapper.
#include "drivers/display/display_factory.h"

#include "common/error.h"
#include "drivers/display/display_backends.h"
#include "drivers/display/kms_display.h"

namespace avatarbooth {
namespace {

// The KMS screen behind a ReopeningDisplay. MayWait: a screen not connected now is waited for.
OpenedDisplay openKmsScreen(const DisplaySettings& settings, ReopeningDisplay::FirstOpen first) {
    const Rotation rotation = rotationFromDegrees(settings.rotation);
    const std::string label = "kms " + (settings.drmDevice.empty() ? std::string("/dev/dri") : settings.drmDevice) +
                              (settings.connector.empty() ? std::string() : " " + settings.connector);
    auto display = std::make_unique<ReopeningDisplay>(
        [settings] { return std::make_unique<KmsDisplay>(settings); }, label, first,
        rotatedSize({settings.width, settings.height}, rotation), rotation);
    OpenedDisplay out;
    out.reopening = display.get();
    out.display = std::move(display);
    return out;
}

bool noWindow(const DisplaySettings& settings) {
    const DisplayBackend* window = findBackend(displayBackends(), "window");
    return window == nullptr || !window->probe(settings).usable;
}

}  // namespace

bool displayWaitsForScreen(const DisplaySettings& settings, std::string* what) {
    if (settings.backend != "kms" && settings.backend != "auto") return false;
    if (kmsScreenAvailable(settings.drmDevice, settings.connector)) return false;
    if (settings.backend == "auto" && !noWindow(settings)) return false;
    return kmsScreenExpected(settings.drmDevice, settings.connector, what);
}

OpenedDisplay createDisplay(const DisplaySettings& settings) {
    rotationFromDegrees(settings.rotation);  // a bad rotation is a config error whichever backend is chosen
    const std::span<const DisplayBackend> table = displayBackends();
    OpenedDisplay out;
    if (settings.backend != "auto") {
        const DisplayBackend* entry = findBackend(table, settings.backend);
        if (!entry)
            throw BoothError(ErrorKind::BadConfig, "display.backend",
                             "\"" + settings.backend + "\" is not a display (" + backendWordList(table) + ")");
        if (settings.backend == "kms") {
            // A board's screen may be off now and come later; a machine without a KMS connector fails as before.
            const bool expected = kmsScreenExpected(settings.drmDevice, settings.connector);
            out = openKmsScreen(settings, expected ? ReopeningDisplay::FirstOpen::MayWait
                                                   : ReopeningDisplay::FirstOpen::MustSucceed);
        } else {
            out.display = entry->open(settings);
        }
        out.description = "display: " + out.display->describe();
        return out;
    }
    // A backend whose probe passes may still fail to open (an X server that refuses us, a GPU EGL cannot drive):
    // it is passed over like one whose probe failed, and the walk goes on after it.
    std::vector<PassedBackend> passed;
    for (std::size_t from = 0;;) {
        BackendChoice<DisplayBackend> choice = probeBackends(table, settings, from);
        passed.insert(passed.end(), choice.passed.begin(), choice.passed.end());
        if (!choice.backend) throw BoothError(ErrorKind::Device, "display", "no display backend opens: " + passedOver(passed));
        // The last resort is headless; but a board with a KMS connector and no screen on it now (a monitor switched
        // off at start-up) waits for its screen instead, or it would stay headless until the next restart.
        // (Only for want of a screen: a screen that is connected but held by a desktop's compositor stays
        // headless, as a developer running the booth beside their desktop expects.)
        if (choice.backend == &table.back() && !kmsScreenAvailable(settings.drmDevice, settings.connector) &&
            kmsScreenExpected(settings.drmDevice, settings.connector)) {
            out = openKmsScreen(settings, ReopeningDisplay::FirstOpen::MayWait);
            if (!out.reopening->status().ok) {
                // "display: kms /dev/dri waiting for a screen (auto: kms: /dev/dri/card1: no screen connected
                // (HDMI-A-1 not connected); window: $DISPLAY is not set)": the passed-over reasons say why.
                const std::string label = out.display->describe();
                out.description = "display: " + label.substr(0, label.find(" (")) + " (auto: " + passedOver(passed) + ")";
            } else {
                out.description = "display: " + out.display->describe() + " (auto: " + passedOver(passed) + ")";
            }
            return out;
        }
        try {
            if (choice.backend->name == "kms") out = openKmsScreen(settings, ReopeningDisplay::FirstOpen::MustSucceed);
            else out.display = choice.backend->open(settings);
        } catch (const BoothError& e) {
            passed.push_back({std::string(choice.backend->name), e.what()});
            from = static_cast<std::size_t>(choice.backend - table.data()) + 1;
            continue;
        }
        choice.passed = std::move(passed);
        out.description = "display: " + out.display->describe() + " (" + autoReason(choice) + ")";
        return out;
    }
}

}  // namespace avatarbooth
