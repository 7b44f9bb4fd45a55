// `avatarbooth config` as an operator runs it: the printed default is a valid file, a broken file is refused with
// file, line and key of every mistake and exit code 6, and the Markdown reference is the README's.
#include "run_binary.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <fstream>

using namespace avatarbooth::test;

namespace {

void write(const std::filesystem::path& file, const std::string& text) {
    std::ofstream out(file, std::ios::binary);
    out << text;
}

}  // namespace

TEST(ConfigCli, PrintedDefaultChecksClean) {
    const auto dir = scratchDir("config_cli_default");
    const auto file = dir / "booth.toml";
    const CommandResult printed = runAvatarbooth("config --print-default > " + file.string());
    ASSERT_EQ(printed.exitCode, 0) << printed.output;
    const CommandResult checked = runAvatarbooth("config --check " + file.string());
    EXPECT_EQ(checked.exitCode, 0) << checked.output;
    EXPECT_EQ(checked.output, file.string() + ": OK\n");
}

TEST(ConfigCli, BrokenFileNamesFileLineAndKey) {
    const auto dir = scratchDir("config_cli_broken");
    const auto file = dir / "booth.toml";
    write(file, "[camera]\nbackend = \"sim\"\n\n[display]\nrotation = 45\n");
    const CommandResult r = runAvatarbooth("config --check " + file.string());
    EXPECT_EQ(r.exitCode, 6) << r.output;
    EXPECT_EQ(r.output, "avatarbooth: error: " + file.string() + ":5: display.rotation: must be 0, 90, 180 or 270\n");
}

TEST(ConfigCli, EveryMistakeIsListedAtOnce) {
    const auto dir = scratchDir("config_cli_three");
    const auto file = dir / "booth.toml";
    write(file, "[camera]\nbackend = \"webcam\"\n\n[display]\nrotation = 45\nbogus = 1\n");
    const CommandResult r = runAvatarbooth("config --check " + file.string());
    EXPECT_EQ(r.exitCode, 6) << r.output;
    const std::string prefix = "avatarbooth: error: " + file.string();
    EXPECT_EQ(r.output, prefix + ":2: camera.backend: \"webcam\" is not one of \"auto\", \"v4l2\", \"libcamera\" or \"sim\"\n" +
                            prefix + ":5: display.rotation: must be 0, 90, 180 or 270\n" + prefix +
                            ":6: display.bogus: unknown key (see the reference booth.toml for the keys there are)\n");
}

TEST(ConfigCli, OneActionAtATime) {
    EXPECT_EQ(runAvatarbooth("config").exitCode, 2);
    EXPECT_EQ(runAvatarbooth("config --print-default --reference").exitCode, 2);
    const CommandResult reference = runAvatarbooth("config --reference");
    EXPECT_EQ(reference.exitCode, 0);
    EXPECT_EQ(reference.output.rfind("**`[fit]`**", 0), 0u) << reference.output.substr(0, 200);
}
