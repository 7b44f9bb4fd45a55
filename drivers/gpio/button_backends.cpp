// The buttons table: each backend's probe and how it opens its buttons and lamps.
#include "drivers/gpio/button_backends.h"

#include "drivers/gpio/button_board.h"
#include "drivers/gpio/button_timeline.h"
#include "drivers/gpio/debounced_buttons.h"
#include "drivers/gpio/gpiod_lines.h"

#include <algorithm>
#include <chrono>

namespace avatarbooth {
namespace {

std::vector<std::string> lampNames(const GpioSettings& s) {
    std::vector<std::string> out;
    for (const auto& l : s.lamps) out.push_back(l.name);
    return out;
}

// Where libgpiod can ask the kernel to debounce (2.x), it filters glitches this short (interference on a long
// button cable) before they reach the software debouncer. Kept short: the kernel reports an edge only once the
// line has held its level this long, so every press comes this much later, and the booth's rule is a press on its
// edge (the software debouncer, debounce_ms, takes care of contact bounce without delaying the press).
constexpr std::chrono::microseconds kKernelGlitchFilter{5000};

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
        const DebounceSettings debounce = debounceFor(settings, b);
        const auto glitch = gpiodKernelDebounce()
                                ? std::min(kKernelGlitchFilter,
                                           std::chrono::duration_cast<std::chrono::microseconds>(debounce.period))
                                : std::chrono::microseconds{0};
        inputs.push_back({b.offset, b.bias, b.name + " button", glitch});
        config.push_back({b.name, debounce});
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
