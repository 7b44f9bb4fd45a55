// The Debian package: built by CPack from this build, inspected with dpkg-deb (control fields, maintainer scripts,
// the files and where they go), unpacked into a scratch root with dpkg -x, and the installed binary run from there
// (--version, check), so the installed layout works, not only the build tree.
#include "run_shell.h"
#include "test_paths.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <array>
#include <fstream>
#include <map>
#include <regex>

namespace fs = std::filesystem;
using namespace avatarbooth::test;

namespace {

// The build tree: <build>/app/avatarbooth.
fs::path buildDir() { return binary().parent_path().parent_path(); }

std::string field(const std::string& control, const std::string& name) {
    std::smatch m;
    if (std::regex_search(control, m, std::regex("(^|\n) ?" + name + ": ([^\n]*)"))) return m[2];
    return "";
}

}  // namespace

TEST(PackageDeb, BuildsInspectsUnpacksAndRuns) {
    const fs::path dir = scratchDir("package_deb");
    // cpack installs the build tree (nothing is compiled: the tests depend on the built binary).
    CommandResult r = runShell("cd " + dir.string() + " && cpack --config " + (buildDir() / "CPackConfig.cmake").string() +
                            " -G DEB -B " + dir.string() + " 2>&1");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    fs::path deb;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().extension() == ".deb") deb = e.path();
    ASSERT_FALSE(deb.empty()) << r.output;
    EXPECT_TRUE(std::regex_match(deb.filename().string(), std::regex("avatarbooth_[0-9.]+_[a-z0-9]+\\.deb"))) << deb;

    // Control fields and maintainer scripts.
    r = runShell("dpkg-deb -I " + deb.string() + " 2>&1");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::string info = r.output;
    EXPECT_EQ(field(info, "Package"), "avatarbooth");
    const std::string depends = field(info, "Depends");
    // Library packages as dpkg-shlibdeps names them on bookworm or trixie (libgpiod2 -> libgpiod3, cpp-httplib's
    // soname, the t64 renames: libcups2t64, libasound2t64).
    for (const char* p : {"libdlib-data", "libopencv-core", "libdlib19", "libgpiod[23]\\b", "libcamera", "libsystemd0",
                          "fonts-dejavu-core", "systemd", "libqrencode4", "libcpp-httplib0\\.[0-9]+", "libcairo2",
                          "libcups2", "libasound2", "libvorbisfile3", "libsamplerate0", "sound-theme-freedesktop",
                          "libwebpmux3"})
        EXPECT_TRUE(std::regex_search(depends, std::regex(p))) << p << " not in Depends: " << depends;
    // The control members as dpkg-deb lists them (trixie's ends the line after a member without an interpreter).
    EXPECT_TRUE(std::regex_search(info, std::regex("\\spostinst\\s"))) << info;
    EXPECT_TRUE(std::regex_search(info, std::regex("\\sconffiles\\s"))) << info;
    r = runShell("dpkg-deb --ctrl-tarfile " + deb.string() + " | tar -xO ./postinst");
    ASSERT_EQ(r.exitCode, 0);
    EXPECT_NE(r.output.find("systemd-sysusers avatarbooth.conf"), std::string::npos) << r.output;
    // It enables and starts nothing the operator did not ask for.
    EXPECT_FALSE(std::regex_search(r.output, std::regex("\n[ \t]*(systemctl|deb-systemd-invoke) [^\n]*\\b(start|enable)\\b")))
        << r.output;
    r = runShell("dpkg-deb --ctrl-tarfile " + deb.string() + " | tar -xO ./conffiles");
    EXPECT_EQ(r.output, "/etc/avatarbooth/booth.toml\n");

    // Files and where they go.
    r = runShell("dpkg-deb -c " + deb.string());
    ASSERT_EQ(r.exitCode, 0);
    for (const char* path : {"./usr/bin/avatarbooth", "./etc/avatarbooth/booth.toml", "./usr/share/avatarbooth/strings.toml",
                             "./usr/lib/systemd/system/avatarbooth.service",
                             "./usr/lib/systemd/system/avatarbooth-retention.service",
                             "./usr/lib/systemd/system/avatarbooth-retention.timer",
                             "./usr/lib/systemd/system/avatarbooth-share.service", "./usr/lib/tmpfiles.d/avatarbooth.conf",
                             "./usr/lib/sysusers.d/avatarbooth.conf", "./usr/lib/udev/rules.d/60-avatarbooth.rules",
                             "./usr/share/avatarbooth/firmware/avatarbooth-overlay.dts",
                             "./usr/share/avatarbooth/firmware/config.txt.fragment",
                             "./usr/share/doc/avatarbooth/README.md",
                             // the MakeHuman base head the build made
                             "./usr/share/avatarbooth/base_head/base_head.glb",
                             "./usr/share/avatarbooth/base_head/base_head.features.json",
                             "./usr/share/avatarbooth/base_head/base_head.modifiers.bin",
                             "./usr/share/avatarbooth/base_head/base_head.skin.png"})
        EXPECT_NE(r.output.find(std::string(path) + "\n"), std::string::npos) << path << " not in the package";

    // Unpacked into a scratch root; the binary found there runs and finds its own strings file and config.
    const fs::path root = dir / "root";
    r = runShell("dpkg -x " + deb.string() + " " + root.string() + " 2>&1");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const fs::path installed = root / "usr/bin/avatarbooth";
    r = runShell(installed.string() + " --version 2>&1");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(std::regex_match(r.output, std::regex("avatarbooth [0-9]+\\.[0-9]+\\.[0-9]+\n"))) << r.output;

    // The installed config, with the data folder moved into the scratch root (the one thing a test may not touch).
    std::ifstream in(root / "etc/avatarbooth/booth.toml");
    std::string config((std::istreambuf_iterator<char>(in)), {});
    const std::string from = "directory = \"/var/lib/avatarbooth/sessions\"";
    ASSERT_NE(config.find(from), std::string::npos);
    config.replace(config.find(from), from.size(), "directory = \"" + (root / "var/lib/avatarbooth/sessions").string() + "\"");
    std::ofstream(root / "etc/avatarbooth/booth.toml") << config;
    // Run from outside the source tree, so only the installed strings file can be found.
    r = runShell("cd / && env -u AVATARBOOTH_ASSET_DIR " + installed.string() + " check --json --config " +
              (root / "etc/avatarbooth/booth.toml").string() + " 2>/dev/null");
    const nlohmann::json report = nlohmann::json::parse(r.output);
    std::map<std::string, std::string> last;  // check -> status of its last line
    std::map<std::string, std::string> message;
    for (const auto& c : report.at("checks")) {
        const std::string check = c.at("check").get<std::string>();
        last[check] = c.at("status").get<std::string>();
        message[check] += c.at("message").get<std::string>() + "\n";
    }
    EXPECT_EQ(last["config"], "OK") << message["config"];
    EXPECT_EQ(last["strings"], "OK") << message["strings"];
    EXPECT_NE(message["strings"].find((root / "usr/share/avatarbooth/strings.toml").string()), std::string::npos)
        << message["strings"];
    EXPECT_EQ(last["landmarks"], "OK") << message["landmarks"];
    EXPECT_EQ(last["base head"], "OK") << message["base head"];
    EXPECT_NE(message["base head"].find((root / "usr/share/avatarbooth/base_head").string()), std::string::npos)
        << message["base head"];
    EXPECT_EQ(last["sessions"], "OK") << message["sessions"];
    // The shipped config says "auto" everywhere: on a machine without the hardware, warnings and exit code 0.
    EXPECT_EQ(r.exitCode, report.at("failures").get<int>() == 0 ? 0 : 8) << r.output;
}
