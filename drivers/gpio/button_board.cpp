// Choosing the buttons and lamps backend through the buttons table, and joining the keyboard to its buttons.
#include "drivers/gpio/button_board.h"

#include "common/error.h"

#include <set>

namespace avatarbooth {
namespace {

// The settings besides the backend's name (chooseButtonBackend checks that).
void validate(const GpioSettings& s) {
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

}  // namespace

std::vector<std::string> configuredButtonNames(const GpioSettings& settings) {
    std::vector<std::string> out;
    for (const auto& b : settings.buttons) out.push_back(b.name);
    return out;
}

DebounceSettings debounceFor(const GpioSettings& settings, const ButtonSettings& button) {
    return {std::chrono::milliseconds(settings.debounceMs), button.activeLow};
}

BackendChoice<ButtonBackend> chooseButtonBackend(const GpioSettings& settings) {
    if (settings.backend == "auto") return probeBackends(buttonBackends(), settings);
    BackendChoice<ButtonBackend> named;
    named.backend = findBackend(buttonBackends(), settings.backend);
    if (!named.backend)
        throw BoothError(ErrorKind::BadConfig, "gpio.backend",
                         "\"" + settings.backend + "\" is not a buttons backend (" + backendWordList(buttonBackends()) + ")");
    return named;
}

ButtonBoard openButtonBoard(const GpioSettings& settings, Clock& clock) {
    validate(settings);
    // The table ends with the sim, which is always usable: "auto" always chooses.
    const BackendChoice<ButtonBackend> choice = chooseButtonBackend(settings);
    ButtonBoard board;
    board.description = "buttons: " + std::string(choice.backend->name) +
                        (settings.backend == "auto" ? " (" + autoReason(choice) + ")" : std::string()) + "; ";
    OpenedButtons opened = choice.backend->open(settings, clock);
    board.lamps = std::move(opened.lamps);
    board.simLamps = opened.simLamps;

    std::vector<std::unique_ptr<Buttons>> sources;
    sources.push_back(std::move(opened.buttons));
    auto keyboard = std::make_unique<KeyboardButtons>(settings.keys, configuredButtonNames(settings));
    board.keyboard = keyboard.get();
    sources.push_back(std::move(keyboard));
    board.buttons = std::make_unique<MergedButtons>(std::move(sources));
    board.description += board.buttons->describe();
    if (board.lamps) board.description += "; lamps: " + board.lamps->describe();
    return board;
}

}  // namespace avatarbooth
