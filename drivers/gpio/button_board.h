// Opening the booth's buttons and lamps from GpioSettings: GPIO (libgpiod) or the simulation, plus keyboard keys.
#pragma once

#include "drivers/gpio/button_backends.h"
#include "drivers/gpio/buttons.h"
#include "common/clock.h"
#include "drivers/gpio/debouncer.h"
#include "drivers/gpio/gpio_settings.h"
#include "drivers/gpio/keyboard_buttons.h"
#include "drivers/gpio/lamps.h"

#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

struct ButtonBoard {
    std::unique_ptr<Buttons> buttons;   // the GPIO or scripted buttons merged with the keyboard
    KeyboardButtons* keyboard = nullptr;  // inside `buttons`: hand the display's key events to keyboard->feed()
    std::unique_ptr<Lamps> lamps;       // GPIO lamps, or SimLamps (recording) with the sim
    SimLamps* simLamps = nullptr;       // `lamps` when simulated (to draw them on screen), else null
    std::string description;            // for the start-up log: which backend and why
};

// The backend openButtonBoard opens: the one named (not probed), or for "auto" the first of buttonBackends() whose
// probe passes, with why the earlier ones were passed over. A name the table does not have is BoothError
// BadConfig.
BackendChoice<ButtonBackend> chooseButtonBackend(const GpioSettings& settings);

// Checks the settings (unique names and offsets, debounce 0-1000 ms, known backend; BoothError BadConfig naming
// the field) and opens the backend chooseButtonBackend gives: for "auto" gpiod when the chip can be opened and the
// sim otherwise. The sim runs on `clock` from now on (its timeline counts from this call), which must outlive the
// board.
ButtonBoard openButtonBoard(const GpioSettings& settings, Clock& clock);

// The configured buttons' names, in order.
std::vector<std::string> configuredButtonNames(const GpioSettings& settings);

// The debounce settings of one configured button.
DebounceSettings debounceFor(const GpioSettings& settings, const ButtonSettings& button);

}  // namespace avatarbooth
