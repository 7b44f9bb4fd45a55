// libFuzzer target: the configuration parser (config/booth_config parseBoothConfig: TOML, then the strict checks
// of every table and key). Every input must give a configuration or a BoothError.
#include "common/error.h"
#include "config/booth_config.h"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        (void)avatarbooth::parseBoothConfig(std::string(reinterpret_cast<const char*>(data), size), "fuzz.toml");
    } catch (const avatarbooth::BoothError&) {
    }
    return 0;
}
