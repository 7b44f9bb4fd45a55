// GPIO input and output lines through libgpiod 1.6 (the GPIO character device). All use of the gpiod API is in
// gpiod_lines.cpp; this header names no gpiod type, so a libgpiod 2.x backend can replace that one file.
#pragma once

#include "drivers/gpio/gpio_settings.h"
#include "drivers/gpio/raw_lines.h"

#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

struct InputLineRequest {
    unsigned offset = 0;
    LineBias bias = LineBias::PullUp;
    std::string label;  // what the line is for, used in errors: "start button"
};

struct OutputLineRequest {
    unsigned offset = 0;
    bool initialHigh = false;
    std::string label;  // "flash lamp"
};

// Requests the lines for both-edge events. `chip`: label, name, path or number (GpioSettings::chip). Throws
// BoothError(Device) naming the chip and line when the chip is missing or not accessible, a line does not exist
// or is already in use (and by whom). A bias the controller refuses is dropped (noted in describe()).
std::unique_ptr<RawInputLines> openGpiodInputLines(const std::string& chip, const std::vector<InputLineRequest>& lines,
                                                   const std::string& consumer);
// Requests the lines as outputs at their initial levels; errors as above.
std::unique_ptr<RawOutputLines> openGpiodOutputLines(const std::string& chip,
                                                     const std::vector<OutputLineRequest>& lines,
                                                     const std::string& consumer);
// Whether `chip` can be opened; when not, `why` says why (no such chip, permission denied) and lists the chips
// that exist.
bool gpiodChipAvailable(const std::string& chip, std::string* why = nullptr);

// What `avatarbooth check` says about one configured line, found without requesting it.
struct GpioLineStatus {
    unsigned offset = 0;
    bool exists = false;   // the chip has a line at this offset
    bool used = false;     // requested by someone (the kernel or a process) right now
    std::string consumer;  // who, when used
    std::string name;      // the line's name from the device tree ("GPIO17"), when it has one
};

// The state of `offsets` on `chip` (label, name, path or number). Throws BoothError(Device) when the chip cannot be
// opened; `chipName` gets "gpiochip0 [pinctrl-bcm2711]".
std::vector<GpioLineStatus> gpiodLineStatus(const std::string& chip, const std::vector<unsigned>& offsets,
                                            std::string* chipName = nullptr);

}  // namespace avatarbooth
