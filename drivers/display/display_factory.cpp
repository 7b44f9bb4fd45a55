// Display selection through the display table: a backend by name, or the first that works.
#include "drivers/display/display_factory.h"

#include "common/error.h"
#include "drivers/display/display_backends.h"

namespace avatarbooth {

OpenedDisplay createDisplay(const DisplaySettings& settings) {
    rotationFromDegrees(settings.rotation);  // a bad rotation is a config error whichever backend is chosen
    const std::span<const DisplayBackend> table = displayBackends();
    OpenedDisplay out;
    if (settings.backend != "auto") {
        const DisplayBackend* entry = findBackend(table, settings.backend);
        if (!entry)
            throw BoothError(ErrorKind::BadConfig, "display.backend",
                             "\"" + settings.backend + "\" is not a display (" + backendWordList(table) + ")");
        out.display = entry->open(settings);
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
        try {
            out.display = choice.backend->open(settings);
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
