// The buttons backends as one table, in the order "auto" tries them: gpiod (libgpiod), then the simulation.
#pragma once

#include "common/backend_table.h"
#include "drivers/gpio/buttons.h"
#include "common/clock.h"
#include "drivers/gpio/gpio_settings.h"
#include "drivers/gpio/lamps.h"

#include <memory>
#include <array>
#include <span>
#include <string_view>

namespace avatarbooth {

// What a buttons backend opens: its buttons (before the keyboard joins them) and its lamps.
struct OpenedButtons {
    std::unique_ptr<Buttons> buttons;
    std::unique_ptr<Lamps> lamps;   // null when no lamp is configured (gpiod)
    SimLamps* simLamps = nullptr;   // `lamps` when simulated, else null
};

// Opens the backend for validated settings; the sim's timeline counts from this call on `clock`. Throws
// BoothError(Device) naming chip and line (gpiod), BadConfig for a bad timeline file (sim).
using OpenButtons = OpenedButtons (*)(const GpioSettings& settings, Clock& clock);
using ButtonBackend = Backend<GpioSettings, OpenButtons>;

// gpiod (usable when the chip opens; no line is requested by the probe), sim (always usable).
// The table's names in its order: the words the configuration accepts after "auto" (read without the table, so
// that the configuration needs none of the drivers).
inline constexpr std::array<std::string_view, 2> kButtonBackendNames{"gpiod", "sim"};
std::span<const ButtonBackend> buttonBackends();

}  // namespace avatarbooth
