// The appliance's system files, checked by the real Debian tools: the service unit (systemd-analyze verify, and its
// `systemd-analyze security` exposure at most 2.0), tmpfiles.d and sysusers.d applied to a scratch root, the
// device-tree overlay compiled by dtc without warnings, and its GPIO numbers equal to booth.toml's and the README's.
#include "run_shell.h"
#include "test_paths.h"

#include "config/booth_config.h"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>

namespace fs = std::filesystem;
using namespace avatarbooth;
using namespace avatarbooth::test;

namespace {

const fs::path kSource = AVATARBOOTH_TEST_SOURCE_DIR;

// stdout and stderr together.
CommandResult shell(const std::string& cmd) { return runShell(cmd + " 2>&1"); }

// The tools come from Debian packages tests/setup.sh installs; a missing one is a failed test, not a skip.
void requireTool(const std::string& tool, const std::string& package) {
    ASSERT_EQ(shell("command -v " + tool).exitCode, 0) << tool << " is missing: apt-get install " << package;
}

// A unit as installed, but starting the binary just built (verify checks that ExecStart exists).
fs::path unitForVerify(const fs::path& dir, const std::string& name = "avatarbooth.service") {
    std::string unit = readFileBytes(kSource / "systemd" / name);
    unit = std::regex_replace(unit, std::regex("/usr/bin/avatarbooth"), binary().string());
    const fs::path out = dir / name;
    std::ofstream(out) << unit;
    return out;
}

std::string modeString(const fs::path& p) {
    struct stat st {};
    if (::stat(p.c_str(), &st) != 0) return "missing";
    char buf[8];
    std::snprintf(buf, sizeof buf, "%04o", st.st_mode & 07777);
    return buf;
}

}  // namespace

TEST(ApplianceSystemd, EveryUnitVerifies) {
    requireTool("systemd-analyze", "systemd");
    const fs::path dir = scratchDir("appliance_verify");
    std::string units;
    for (const char* name : {"avatarbooth.service", "avatarbooth-retention.service", "avatarbooth-retention.timer",
                             "avatarbooth-share.service"})
        units += " " + unitForVerify(dir, name).string();
    const CommandResult r = shell("systemd-analyze verify" + units);
    EXPECT_EQ(r.exitCode, 0) << r.output;
    // verify reports unknown keys and bad values as warnings with exit code 0: none may appear either.
    EXPECT_EQ(r.output, "") << r.output;
}

TEST(ApplianceSystemd, ServiceUnitIsNotifyWithWatchdogAndRestart) {
    const std::string unit = readFileBytes(kSource / "systemd/avatarbooth.service");
    EXPECT_NE(unit.find("\nType=notify\n"), std::string::npos);
    EXPECT_NE(unit.find("\nRestart=always\n"), std::string::npos);
    EXPECT_NE(unit.find("\nUser=avatarbooth\n"), std::string::npos);
    EXPECT_NE(unit.find("\nSupplementaryGroups=video gpio render input\n"), std::string::npos);
    // $CACHE_DIRECTORY, where the converted landmark model is kept (fit/face/model_cache.h).
    EXPECT_NE(unit.find("\nCacheDirectory=avatarbooth\n"), std::string::npos);
    // The kiosk pings at half of WatchdogSec while its loop runs: long enough for a slow frame, and not off.
    std::smatch m;
    ASSERT_TRUE(std::regex_search(unit, m, std::regex("\nWatchdogSec=([0-9]+)s\n"))) << "WatchdogSec=Ns missing";
    EXPECT_GE(std::stoi(m[1]), 3);
    EXPECT_LE(std::stoi(m[1]), 60);
}

// The share service (issue 23): off unless enabled, not restarted when booth.toml says sharing is off (exit 6), and
// sandboxed to reading the sessions folder and listening on the web ports.
TEST(ApplianceSystemd, ShareUnitMayOnlyReadTheSessionsAndListen) {
    const std::string unit = readFileBytes(kSource / "systemd/avatarbooth-share.service");
    EXPECT_NE(unit.find("\nExecStart=/usr/bin/avatarbooth share --config /etc/avatarbooth/booth.toml\n"), std::string::npos);
    EXPECT_NE(unit.find("\nType=notify\n"), std::string::npos);
    EXPECT_NE(unit.find("\nRestartPreventExitStatus=6\n"), std::string::npos);
    EXPECT_NE(unit.find("\nUser=avatarbooth\n"), std::string::npos);
    EXPECT_NE(unit.find("\nProtectSystem=strict\n"), std::string::npos);
    EXPECT_NE(unit.find("\nTemporaryFileSystem=/var:ro\n"), std::string::npos);
    EXPECT_NE(unit.find("\nBindReadOnlyPaths=/var/lib/avatarbooth/sessions\n"), std::string::npos);
    EXPECT_EQ(unit.find("StateDirectory="), std::string::npos) << "it writes nowhere";
    EXPECT_EQ(unit.find("ReadWritePaths="), std::string::npos) << "it writes nowhere";
    EXPECT_NE(unit.find("\nSocketBindDeny=any\n"), std::string::npos);
    EXPECT_NE(unit.find("\nCapabilityBoundingSet=CAP_NET_BIND_SERVICE\n"), std::string::npos);
    // The kiosk stays off the network.
    EXPECT_NE(readFileBytes(kSource / "systemd/avatarbooth.service").find("\nPrivateNetwork=yes\n"), std::string::npos);
}

TEST(ApplianceSystemd, SecurityExposureAtMostTwo) {
    requireTool("systemd-analyze", "systemd");
    const fs::path dir = scratchDir("appliance_security");
    for (const std::string name : {"avatarbooth.service", "avatarbooth-retention.service", "avatarbooth-share.service"}) {
        const fs::path unit = unitForVerify(dir, name);
        // --offline: judge the file itself, not a loaded unit (works in a container without a running systemd).
        const CommandResult r = shell("systemd-analyze security --offline=true --no-pager " + unit.string());
        std::smatch m;
        ASSERT_TRUE(std::regex_search(r.output, m, std::regex("Overall exposure level for " + name + ": ([0-9.]+)")))
            << r.output;
        const double exposure = std::stod(m[1]);
        std::cout << name << ": systemd-analyze security exposure " << exposure << "\n";
        EXPECT_LE(exposure, 2.0) << r.output;
        // And its own threshold check agrees (exit code non-zero above the threshold, in tenths).
        EXPECT_EQ(shell("systemd-analyze security --offline=true --threshold=20 --no-pager " + unit.string()).exitCode, 0);
    }
}

TEST(ApplianceSystemd, TmpfilesAndSysusersMakeTheUserAndItsFolder) {
    requireTool("systemd-tmpfiles", "systemd");
    const fs::path root = scratchDir("appliance_root");
    fs::create_directories(root / "etc");
    // sysusers.d first, as the package's postinst does: it makes the user tmpfiles.d gives the folder to.
    CommandResult r = shell("systemd-sysusers --root=" + root.string() + " " + (kSource / "systemd/avatarbooth.sysusers").string());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::string passwd = readFileBytes(root / "etc/passwd");
    const std::string group = readFileBytes(root / "etc/group");
    EXPECT_TRUE(std::regex_search(passwd, std::regex("(^|\n)avatarbooth:x:[0-9]+:[0-9]+:[^:]*:/var/lib/avatarbooth:/usr/sbin/nologin\n")))
        << passwd;
    for (const char* g : {"video", "gpio", "render", "input"})
        EXPECT_TRUE(std::regex_search(group, std::regex(std::string("(^|\n)") + g + ":x:[0-9]+:avatarbooth\n"))) << g << "\n" << group;

    r = shell("systemd-tmpfiles --root=" + root.string() + " --create " + (kSource / "systemd/avatarbooth.tmpfiles").string());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(modeString(root / "var/lib/avatarbooth"), "0750");
    EXPECT_EQ(modeString(root / "var/lib/avatarbooth/sessions"), "0750");
    // The cache of the converted landmark model, the booth user's alone (fit/face/model_cache.h looks there).
    EXPECT_EQ(modeString(root / "var/cache/avatarbooth"), "0700");
    // The sessions folder of tmpfiles.d is the one booth.toml ships.
    const BoothConfig shipped = loadBoothConfig(kSource / "app/assets/booth.toml");
    EXPECT_EQ(shipped.sessions.directory, fs::path("/var/lib/avatarbooth/sessions"));
}

TEST(ApplianceFirmware, OverlayCompilesWithoutWarningsAndMatchesTheConfig) {
    requireTool("dtc", "device-tree-compiler");
    const fs::path dir = scratchDir("appliance_dtc");
    const fs::path dtbo = dir / "avatarbooth.dtbo";
    // stderr alone: dtc writes its warnings there.
    const CommandResult r = shell("dtc -@ -I dts -O dtb -o " + dtbo.string() + " " +
                                  (kSource / "firmware/avatarbooth-overlay.dts").string() + " 2>&1 >/dev/null");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(r.output, "") << "dtc warnings:\n" << r.output;
    ASSERT_TRUE(fs::exists(dtbo));

    // The compiled pins, in the overlay's order: start, retake, start lamp, retake lamp, flash lamp.
    const std::string node = "/fragment@0/__overlay__/avatarbooth_pins";
    const CommandResult pins = shell("fdtget -t u " + dtbo.string() + " " + node + " brcm,pins");
    ASSERT_EQ(pins.exitCode, 0) << pins.output;
    EXPECT_EQ(shell("fdtget -t u " + dtbo.string() + " " + node + " brcm,function").output, "0 0 1 1 1\n");
    EXPECT_EQ(shell("fdtget -t u " + dtbo.string() + " " + node + " brcm,pull").output, "2 2 0 0 0\n");

    const BoothConfig shipped = loadBoothConfig(kSource / "app/assets/booth.toml");
    auto buttonOffset = [&](const std::string& name) {
        for (const auto& b : shipped.buttons.buttons) if (b.name == name) return static_cast<int>(b.offset);
        return -1;
    };
    auto lampOffset = [&](const std::string& name) {
        for (const auto& l : shipped.buttons.lamps) if (l.name == name) return static_cast<int>(l.offset);
        return -1;
    };
    const std::vector<int> expected = {buttonOffset("start"), buttonOffset("retake"), lampOffset("start"),
                                       lampOffset("retake"), lampOffset("flash")};
    std::ostringstream want;
    for (std::size_t i = 0; i < expected.size(); ++i) want << (i ? " " : "") << expected[i];
    EXPECT_EQ(pins.output, want.str() + "\n");

    // The boot config fragment passes the same numbers as overlay parameters.
    const std::string fragment = readFileBytes(kSource / "firmware/config.txt.fragment");
    std::ostringstream line;
    line << "dtoverlay=avatarbooth,start=" << expected[0] << ",retake=" << expected[1] << ",start_lamp=" << expected[2]
         << ",retake_lamp=" << expected[3] << ",flash_lamp=" << expected[4] << "\n";
    EXPECT_NE(fragment.find(line.str()), std::string::npos) << "expected in config.txt.fragment: " << line.str();

    // The README's wiring table names the same BCM numbers ("| start button | BCM 17 | ...").
    const std::string readme = readFileBytes(kSource / "README.md");
    const std::vector<std::string> rows = {"start button", "retake button", "start lamp", "retake lamp", "flash lamp"};
    for (std::size_t i = 0; i < rows.size(); ++i)
        EXPECT_NE(readme.find("| " + rows[i] + " | BCM " + std::to_string(expected[i]) + " |"), std::string::npos)
            << "README wiring table row for " << rows[i];
}

TEST(ApplianceFirmware, OverlayParametersMoveThePins) {
    requireTool("dtc", "device-tree-compiler");
    // Each __overrides__ entry points at one cell of brcm,pins: parameter i at byte offset 4 i.
    const fs::path dir = scratchDir("appliance_dtc_params");
    const fs::path dtbo = dir / "avatarbooth.dtbo";
    ASSERT_EQ(shell("dtc -@ -q -I dts -O dtb -o " + dtbo.string() + " " + (kSource / "firmware/avatarbooth-overlay.dts").string()).exitCode, 0);
    const std::vector<std::string> params = {"start", "retake", "start_lamp", "retake_lamp", "flash_lamp"};
    for (std::size_t i = 0; i < params.size(); ++i) {
        const CommandResult r = shell("fdtget -t s " + dtbo.string() + " /__overrides__ " + params[i] + " | tr -d '\\0'");
        // The property is <phandle> "brcm,pins:OFFSET": as a string, fdtget shows the text after the phandle bytes.
        EXPECT_NE(r.output.find("brcm,pins:" + std::to_string(4 * i)), std::string::npos) << params[i] << ": " << r.output;
    }
}

TEST(ApplianceFirmware, UdevRulesCoverTheBoothsDevices) {
    const std::string rules = readFileBytes(kSource / "firmware/60-avatarbooth.rules");
    const std::vector<std::pair<std::string, std::string>> wanted = {
        {"KERNEL==\"gpiochip[0-9]*\"", "GROUP=\"gpio\""},  {"KERNEL==\"video[0-9]*\"", "GROUP=\"video\""},
        {"KERNEL==\"media[0-9]*\"", "GROUP=\"video\""},    {"KERNEL==\"card[0-9]*\"", "GROUP=\"video\""},
        {"KERNEL==\"renderD[0-9]*\"", "GROUP=\"render\""}};
    for (const auto& [match, group] : wanted) {
        std::istringstream in(rules);
        std::string line;
        bool found = false;
        while (std::getline(in, line))
            if (line.rfind('#', 0) != 0 && line.find(match) != std::string::npos && line.find(group) != std::string::npos &&
                line.find("MODE=\"0660\"") != std::string::npos)
                found = true;
        EXPECT_TRUE(found) << match << " with " << group;
    }
}
