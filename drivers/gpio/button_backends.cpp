// The buttons table: each backend's probe and how it opens its buttons and lamps.
#include "drivers/gpio/button_backends.h"

#include "drivers/gpio/button_board.h"
#include "drivers/gpio/button_timeline.h"
#include "drivers/gpio/debounced_buttons.h"
#include "drivers/gpio/gpiod_lines.h"

namespace avatarbooth {
namespace {

std::vector<std::string> lampNames(const GpioSettings& s) {
    std::vector<std::string> out;
    for (const auto& l : s.lamps) out.push_back(l.name);
    return out;
}

BackendProbe probeGpiod(const GpioSettings& s) {
    std::string why;
    if (!gpiodChipAvailable(s.chip, &why)) return {false, why, ""};
    return {true, "the chip exists", ""};
}

BackendProbe probeSim(const GpioSettings& s) {
    return {true, "scripted buttons" + (s.timeline.empty() ? std::string() : " from " + s.timeline) + " and keyboard keys", ""};
}

OpenedButtons openGpiod(const GpioSettings& settings, Clock&) {
    OpenedButtons out;
    std::vector<InputLineRequest> inputs;
    std::vector<DebouncedLine> config;
    for (const auto& b : settings.buttons) {
        inputs.push_back({b.offset, b.bias, b.name + " button"});
        config.push_back({b.name, debounceFor(settings, b)});
    }
    out.buttons = std::make_unique<DebouncedButtons>(openGpiodInputLines(settings.chip, inputs, settings.consumer),
                                                     std::move(config));
    if (!settings.lamps.empty()) {
        std::vector<OutputLineRequest> outputs;
        std::vector<bool> activeLow;
        for (const auto& l : settings.lamps) {
            outputs.push_back({l.offset, l.activeLow, l.name + " lamp"});  // off at start
            activeLow.push_back(l.activeLow);
        }
        out.lamps = std::make_unique<LineLamps>(openGpiodOutputLines(settings.chip, outputs, settings.consumer),
                                                lampNames(settings), activeLow);
    }
    return out;
}

OpenedButtons openSim(const GpioSettings& settings, Clock& clock) {
    OpenedButtons out;
    const auto names = configuredButtonNames(settings);
    ButtonTimeline timeline{names, {}};
    std::string source = "(none)";
    if (!settings.timeline.empty()) {
        timeline = loadButtonTimeline(settings.timeline, names);
        source = settings.timeline;
    }
    std::vector<DebouncedLine> config;
    // The script gives levels with high = pressed; debouncing applies as on the hardware.
    for (const auto& b : settings.buttons) config.push_back({b.name, {debounceFor(settings, b).period, false}});
    out.buttons = std::make_unique<DebouncedButtons>(
        std::make_unique<ScriptedLines>(std::move(timeline), clock, clock.now(), source), std::move(config));
    auto lamps = std::make_unique<SimLamps>(lampNames(settings), clock);
    out.simLamps = lamps.get();
    out.lamps = std::move(lamps);
    return out;
}

constexpr ButtonBackend kButtonBackends[] = {
    {kButtonBackendNames[0], probeGpiod, openGpiod},
    {kButtonBackendNames[1], probeSim, openSim},
};

}  // namespace

static_assert(std::size(kButtonBackends) == kButtonBackendNames.size(), "a name for every row");

std::span<const ButtonBackend> buttonBackends() { return kButtonBackends; }

}  // namespace avatarbooth
