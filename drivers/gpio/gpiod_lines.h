// GPIO input and output lines through libgpiod (the GPIO character device). All use of the gpiod API is in one
// file per libgpiod generation: gpiod_lines.cpp for 1.6 (bookworm), gpiod2_lines.cpp for 2.x (trixie); the build
// compiles the one pkg-config finds (drivers/gpio/CMakeLists.txt). This header names no gpiod type.
#pragma once

#include "drivers/gpio/gpio_settings.h"
#include "drivers/gpio/raw_lines.h"

#include <chrono>
#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

struct InputLineRequest {
    unsigned offset = 0;
    LineBias bias = LineBias::PullUp;
    std::string label;  // what the line is for, used in errors: "start button"
    // The kernel's debounce (libgpiod 2.x; 1.6 cannot ask for it, see gpiodKernelDebounce()): an edge is reported
    // only once the line has held its new level this long, so every edge comes this much later. 0: none.
    std::chrono::microseconds kernelDebounce{0};
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
    std::chrono::microseconds kernelDebounce{0};  // the kernel's debounce on the line (libgpiod 2.x reports it)
};

// The state of `offsets` on `chip` (label, name, path or number). Throws BoothError(Device) when the chip cannot be
// opened; `chipName` gets "gpiochip0 [pinctrl-bcm2711]".
std::vector<GpioLineStatus> gpiodLineStatus(const std::string& chip, const std::vector<unsigned>& offsets,
                                            std::string* chipName = nullptr);

// "libgpiod 2.2", the library the backend was built against, for logs and `avatarbooth check`.
std::string gpiodLibraryVersion();
// Whether the backend can ask the kernel to debounce input lines (InputLineRequest::kernelDebounce): libgpiod 2.x.
bool gpiodKernelDebounce();

}  // namespace avatarbooth
