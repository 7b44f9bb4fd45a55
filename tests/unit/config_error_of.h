// For the config tests: the message of the BadConfig error a booth.toml text raises.
#pragma once

#include "common/error.h"
#include "config/booth_config.h"

#include <gtest/gtest.h>

#include <string>

namespace avatarbooth::test {

// The message of the BadConfig error the text raises ("" when it raises none).
inline std::string errorOf(const std::string& text) {
    try {
        parseBoothConfig(text, "booth.toml");
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig) << e.what();
        return e.what();
    }
    return "";
}

}  // namespace avatarbooth::test
