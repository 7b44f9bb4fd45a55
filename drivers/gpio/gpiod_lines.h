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

}  // namespace avatarbooth
