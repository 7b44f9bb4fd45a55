// Where tests find the sample data, the built executable and a scratch folder.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace avatarbooth::test {

// ../shared/data next to the project (or $AVATARBOOTH_SHARED_DATA).
inline std::filesystem::path sharedData() {
    if (const char* env = std::getenv("AVATARBOOTH_SHARED_DATA"); env && *env) return env;
    return AVATARBOOTH_TEST_SHARED_DATA;
}

inline bool haveSharedData() { return std::filesystem::is_directory(sharedData() / "frmdb"); }

inline std::filesystem::path binary() { return AVATARBOOTH_TEST_BINARY; }

// A fresh, empty scratch folder for one test.
inline std::filesystem::path scratchDir(const std::string& name) {
    const auto dir = std::filesystem::path(AVATARBOOTH_TEST_WORK_DIR) / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

// The whole of a file's bytes ("" when it cannot be read).
inline std::string readFileBytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Milliseconds from T0 to now, for the figures tests print.
inline double millisecondsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace avatarbooth::test

// Skips the current test (with the reason printed) when ../shared/data is absent.
#define AVATARBOOTH_REQUIRE_SHARED_DATA()                                                              \
    do {                                                                                               \
        if (!::avatarbooth::test::haveSharedData())                                                    \
            GTEST_SKIP() << "sample data not found at " << ::avatarbooth::test::sharedData()          \
                         << " (set AVATARBOOTH_SHARED_DATA); skipping";                                \
    } while (0)
