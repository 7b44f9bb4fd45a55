// The display backends as one table, in the order "auto" tries them: kms, window, headless.
#pragma once

#include "common/backend_table.h"
#include "drivers/display/display.h"
#include "drivers/display/display_settings.h"

#include <memory>
#include <array>
#include <span>
#include <string_view>

namespace avatarbooth {

// Opens the backend's display; throws its BoothError(Device) when it cannot.
using OpenDisplay = std::unique_ptr<Display> (*)(const DisplaySettings& settings);
using DisplayBackend = Backend<DisplaySettings, OpenDisplay>;

// kms (a DRM device with a connected screen), window ($DISPLAY is set), headless (always usable). The probes take
// nothing: no DRM master, no X connection.
// The table's names in its order: the words the configuration accepts after "auto" (read without the table, so
// that the configuration needs none of the drivers).
inline constexpr std::array<std::string_view, 3> kDisplayBackendNames{"kms", "window", "headless"};
std::span<const DisplayBackend> displayBackends();

}  // namespace avatarbooth
