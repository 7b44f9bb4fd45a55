// Settings of the buttons and lamps: which backend, which GPIO chip and lines, debounce, sim timeline, keys.
// Plain structs with the defaults the booth uses; the config file (app/config/) fills them.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace avatarbooth {

// The pull resistor asked of the GPIO controller for an input line.
enum class LineBias {
    AsIs,      // leave the line's bias as the firmware or device tree set it
    PullUp,    // internal pull-up: a button wired to ground reads low when pressed (active-low)
    PullDown,  // internal pull-down: a button wired to 3.3 V reads high when pressed (active-high)
    Disabled,  // no internal pull (external resistors on the board)
};

struct ButtonSettings {
    std::string name;           // what the booth calls the button: "start", "retake"
    unsigned offset = 0;        // line offset on the chip (on a Raspberry Pi: the BCM GPIO number)
    bool activeLow = true;      // pressed reads low: the button connects the line to ground
    LineBias bias = LineBias::PullUp;  // where the controller cannot set a bias, the line is used as it is
};

struct LampSettings {
    std::string name;       // "start" (the start button's lamp), "retake", "flash"
    unsigned offset = 0;    // line offset on the chip
    bool activeLow = false; // the lamp lights with the line low (many relay boards)
};

struct GpioSettings {
    // "gpiod": the GPIO chip below (libgpiod); "sim": the scripted timeline plus keyboard keys; "auto": gpiod when
    // the chip exists, otherwise sim (the start-up log says which and why).
    std::string backend = "auto";
    // The GPIO chip, by label ("pinctrl-bcm2711" on a Pi 4, "pinctrl-rp1" on a Pi 5, a gpio-sim bank's label), name
    // ("gpiochip0"), path ("/dev/gpiochip0") or number ("0").
    std::string chip = "gpiochip0";
    // Buttons on the chip. Defaults: BCM 17 (header pin 11) and 27 (pin 13), each to ground.
    std::vector<ButtonSettings> buttons = {{"start", 17}, {"retake", 27}};
    // Lamps on the chip. Defaults: BCM 22 (pin 15) start button lamp, 23 (pin 16) retake lamp, 24 (pin 18) flash.
    std::vector<LampSettings> lamps = {{"start", 22}, {"retake", 23}, {"flash", 24}};
    // Two reported changes of a button are at least this far apart (see Debouncer); 0 turns debouncing off.
    int debounceMs = 30;
    // The consumer name the lines are requested under (what `gpioinfo` shows as their user).
    std::string consumer = "avatarbooth";
    // Sim: a scripted button timeline file (see button_timeline.h); empty: no scripted presses (keys only).
    std::string timeline;
    // Keyboard keys (X11 keysym names, as the desktop window reports them) → button names; used whenever a
    // display with a keyboard is open, whatever the backend.
    std::map<std::string, std::string> keys = {{"space", "start"}, {"Return", "start"}, {"r", "retake"},
                                               {"BackSpace", "retake"}};
};

}  // namespace avatarbooth
