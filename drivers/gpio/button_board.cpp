// Choosing and opening the buttons and lamps backend.
#include "drivers/gpio/button_board.h"

#include "common/error.h"
#include "drivers/gpio/button_timeline.h"
#include "drivers/gpio/debounced_buttons.h"
#include "drivers/gpio/gpiod_lines.h"

#include <set>

namespace avatarbooth {
namespace {

void validate(const GpioSettings& s) {
    if (s.backend != "auto" && s.backend != "gpiod" && s.backend != "sim")
        throw BoothError(ErrorKind::BadConfig, "gpio.backend",
                         "\"" + s.backend + "\" is not a buttons backend (auto, gpiod or sim)");
    if (s.debounceMs < 0 || s.debounceMs > 1000)
        throw BoothError(ErrorKind::BadConfig, "gpio.debounce_ms",
                         std::to_string(s.debounceMs) + " is out of range (0-1000 ms; 30 is usual)");
    if (s.buttons.empty()) throw BoothError(ErrorKind::BadConfig, "gpio.buttons", "no button is configured");
    std::set<std::string> buttonNames, lampNames;
    std::set<unsigned> offsets;
    const auto checkOffset = [&](unsigned offset, const std::string& what) {
        if (!offsets.insert(offset).second)
            throw BoothError(ErrorKind::BadConfig, what, "line " + std::to_string(offset) + " is used twice");
    };
    for (const auto& b : s.buttons) {
        const std::string what = "gpio button \"" + b.name + "\"";
        if (b.name.empty()) throw BoothError(ErrorKind::BadConfig, "gpio.buttons", "a button has no name");
        if (!buttonNames.insert(b.name).second) throw BoothError(ErrorKind::BadConfig, what, "is configured twice");
        checkOffset(b.offset, what);
    }
    for (const auto& l : s.lamps) {
        const std::string what = "gpio lamp \"" + l.name + "\"";
        if (l.name.empty()) throw BoothError(ErrorKind::BadConfig, "gpio.lamps", "a lamp has no name");
        if (!lampNames.insert(l.name).second) throw BoothError(ErrorKind::BadConfig, what, "is configured twice");
        checkOffset(l.offset, what);
    }
}

std::vector<std::string> buttonNames(const GpioSettings& s) {
    std::vector<std::string> out;
    for (const auto& b : s.buttons) out.push_back(b.name);
    return out;
}

std::vector<std::string> lampNames(const GpioSettings& s) {
    std::vector<std::string> out;
    for (const auto& l : s.lamps) out.push_back(l.name);
    return out;
}

}  // namespace

DebounceSettings debounceFor(const GpioSettings& settings, const ButtonSettings& button) {
    return {std::chrono::milliseconds(settings.debounceMs), button.activeLow};
}

ButtonBoard openButtonBoard(const GpioSettings& settings, Clock& clock) {
    validate(settings);
    ButtonBoard board;
    std::string backend = settings.backend;
    if (backend == "auto") {
        std::string why;
        if (gpiodChipAvailable(settings.chip, &why)) {
            backend = "gpiod";
            board.description = "buttons: gpiod (auto: the chip exists); ";
        } else {
            backend = "sim";
            board.description = "buttons: sim (auto: " + why + "); ";
        }
    } else {
        board.description = "buttons: " + backend + "; ";
    }

    std::vector<std::unique_ptr<Buttons>> sources;
    if (backend == "gpiod") {
        std::vector<InputLineRequest> inputs;
        std::vector<DebouncedLine> config;
        for (const auto& b : settings.buttons) {
            inputs.push_back({b.offset, b.bias, b.name + " button"});
            config.push_back({b.name, debounceFor(settings, b)});
        }
        sources.push_back(std::make_unique<DebouncedButtons>(
            openGpiodInputLines(settings.chip, inputs, settings.consumer), std::move(config)));
        if (!settings.lamps.empty()) {
            std::vector<OutputLineRequest> outputs;
            std::vector<bool> activeLow;
            for (const auto& l : settings.lamps) {
                outputs.push_back({l.offset, l.activeLow, l.name + " lamp"});  // off at start
                activeLow.push_back(l.activeLow);
            }
            board.lamps = std::make_unique<LineLamps>(
                openGpiodOutputLines(settings.chip, outputs, settings.consumer), lampNames(settings), activeLow);
        }
    } else {
        const auto names = buttonNames(settings);
        ButtonTimeline timeline{names, {}};
        std::string source = "(none)";
        if (!settings.timeline.empty()) {
            timeline = loadButtonTimeline(settings.timeline, names);
            source = settings.timeline;
        }
        std::vector<DebouncedLine> config;
        // The script gives levels with high = pressed; debouncing applies as on the hardware.
        for (const auto& b : settings.buttons) config.push_back({b.name, {debounceFor(settings, b).period, false}});
        sources.push_back(std::make_unique<DebouncedButtons>(
            std::make_unique<ScriptedLines>(std::move(timeline), clock, clock.now(), source), std::move(config)));
        auto lamps = std::make_unique<SimLamps>(lampNames(settings), clock);
        board.simLamps = lamps.get();
        board.lamps = std::move(lamps);
    }
    auto keyboard = std::make_unique<KeyboardButtons>(settings.keys, buttonNames(settings));
    board.keyboard = keyboard.get();
    sources.push_back(std::move(keyboard));
    board.buttons = std::make_unique<MergedButtons>(std::move(sources));
    board.description += board.buttons->describe();
    if (board.lamps) board.description += "; lamps: " + board.lamps->describe();
    return board;
}

}  // namespace avatarbooth
