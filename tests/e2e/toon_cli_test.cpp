// End-to-end test of `avatarbooth toon`: a synthetic visitor's photos to a turntable strip, and its exit codes.
#include "test_paths.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using namespace avatarbooth::test;

namespace {

int runToon(const std::string& args, std::string& output) {
    const std::string cmd = binary().string() + " " + args + " 2>&1";
    FILE* pipe = popen(cmd.c_str(), "r");
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), static_cast<int>(buf.size()), pipe)) output += buf.data();
    const int status = pclose(pipe);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(ToonCli, WritesATurntableStripFromAPhotoPair) {
    const fs::path work = scratchDir("e2e_toon_" + std::to_string(getpid()));
    std::string out;
    ASSERT_EQ(runToon("make-visitor --seed 2 -o " + (work / "visitor").string(), out), 0) << out;
    const fs::path v = work / "visitor";
    ASSERT_EQ(runToon("toon --front " + (v / "front.jpg").string() + " --side " + (v / "side.jpg").string() +
                          " --background " + (v / "background.png").string() + " --frames 5 -o " +
                          (work / "toon").string(),
                      out),
              0)
        << out;
    // dlib's 68 points of the front photo guide the drawing (the face parts become regions of their own).
    EXPECT_NE(out.find("with the face's landmarks"), std::string::npos) << out;
    for (int i = 0; i < 5; ++i) {
        const fs::path frame = work / "toon" / ("turntable_00" + std::to_string(i) + ".png");
        EXPECT_FALSE(cv::imread(frame.string()).empty()) << frame;
    }
    EXPECT_FALSE(fs::exists(work / "toon" / "turntable_005.png"));
    std::string missing;
    EXPECT_EQ(runToon("toon --front " + (work / "nope.jpg").string() + " --side " + (v / "side.jpg").string() +
                          " -o " + (work / "toon2").string(),
                      missing),
              3)
        << missing;
    EXPECT_FALSE(fs::exists(work / "toon2"));
}

}  // namespace
