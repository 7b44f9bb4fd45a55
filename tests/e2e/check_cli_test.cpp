// `avatarbooth check` as an operator runs it: a simulated booth's config passes, a config asking for hardware this
// machine lacks FAILs with a non-zero exit code, a broken config FAILs naming file, line and key, --json parses.
#include "run_binary.h"
#include "test_paths.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

namespace fs = std::filesystem;
using namespace avatarbooth::test;

namespace {

// stdout only (the JSON); stderr kept apart.
CommandResult run(const std::string& args, const fs::path& dir) { return runAvatarboothSplit(args, dir); }

// The statuses of one check (e.g. "camera") in a --json report.
std::vector<std::string> statusesOf(const nlohmann::json& report, const std::string& check) {
    std::vector<std::string> out;
    for (const auto& c : report.at("checks"))
        if (c.at("check") == check) out.push_back(c.at("status").get<std::string>());
    return out;
}

std::string messagesOf(const nlohmann::json& report, const std::string& check) {
    std::string out;
    for (const auto& c : report.at("checks"))
        if (c.at("check") == check) out += c.at("message").get<std::string>() + "\n";
    return out;
}

}  // namespace

TEST(CheckCli, SimulatedBoothIsReady) {
    const fs::path dir = scratchDir("check_sim");
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[camera]\nbackend = \"sim\"\n[buttons]\nbackend = \"sim\"\n[display]\nbackend = \"headless\"\n"
                          << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n";
    fs::create_directories(dir / "sessions");
    const CommandResult text = run("check --config " + config.string(), dir);
    EXPECT_EQ(text.exitCode, 0) << text.output << text.errors;
    EXPECT_NE(text.output.find("OK   config    " + config.string() + " is valid"), std::string::npos) << text.output;
    EXPECT_NE(text.output.find("check: ready"), std::string::npos) << text.output;

    const CommandResult json = run("check --json --config " + config.string(), dir);
    ASSERT_EQ(json.exitCode, 0) << json.output << json.errors;
    const nlohmann::json report = nlohmann::json::parse(json.output);
    EXPECT_TRUE(report.at("ok").get<bool>());
    EXPECT_EQ(report.at("failures").get<int>(), 0);
    for (const char* check : {"config", "gpio", "display", "landmarks", "strings", "sessions", "share", "print"}) {
        const auto s = statusesOf(report, check);
        ASSERT_FALSE(s.empty()) << check;
        EXPECT_EQ(s.back(), "OK") << check << ": " << messagesOf(report, check);
    }
    EXPECT_NE(messagesOf(report, "sessions").find("MB free"), std::string::npos);
    EXPECT_EQ(messagesOf(report, "share").rfind("off ([share] enabled = false)", 0), 0u) << messagesOf(report, "share");
    EXPECT_EQ(messagesOf(report, "print").rfind("off ([print] enabled = false)", 0), 0u) << messagesOf(report, "print");
    // The sound card: this machine has none (a container) or some; either way the check says which.
    const std::string sound = messagesOf(report, "sound");
    EXPECT_NE(sound.find("device default, volume 80%; "), std::string::npos) << sound;
    EXPECT_TRUE(sound.find("no sound card found") != std::string::npos || sound.find("sound card 0: ") != std::string::npos)
        << sound;
    EXPECT_NE(messagesOf(report, "landmarks").find("loads"), std::string::npos);
    // The sim camera is OK whatever real cameras this machine has.
    EXPECT_EQ(statusesOf(report, "camera").back(), "OK");
}

// The visitors' page service, on: where it listens and what the QR codes link; a TLS key it cannot read fails.
TEST(CheckCli, ShareServiceIsReported) {
    const fs::path dir = scratchDir("check_share");
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[camera]\nbackend = \"sim\"\n[buttons]\nbackend = \"sim\"\n[display]\nbackend = \"headless\"\n"
                          << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n"
                          << "[share]\nenabled = true\nlisten = \"10.42.0.1:8080\"\n";
    fs::create_directories(dir / "sessions");
    const CommandResult on = run("check --json --config " + config.string(), dir);
    const nlohmann::json report = nlohmann::json::parse(on.output);
    EXPECT_EQ(messagesOf(report, "share").rfind("on: avatarbooth-share listens on 10.42.0.1:8080 (http), QR codes link "
                                                "http://10.42.0.1:8080/s/<token>, pages live 168 h",
                                                0),
              0u)
        << messagesOf(report, "share");
    std::ofstream(config, std::ios::app) << "tls_certificate = \"" << (dir / "none.pem").string() << "\"\n"
                                         << "tls_key = \"" << (dir / "none.key").string() << "\"\n";
    const CommandResult tls = run("check --json --config " + config.string(), dir);
    EXPECT_EQ(tls.exitCode, 6) << tls.output;
    const nlohmann::json failed = nlohmann::json::parse(tls.output);
    EXPECT_EQ(statusesOf(failed, "share").back(), "FAIL");
    EXPECT_NE(messagesOf(failed, "share").find("none.pem is not readable"), std::string::npos) << messagesOf(failed, "share");
}

// Printing on with no CUPS scheduler to ask: the print queue FAILs, saying so, at once (a live queue's states are
// checked against a real cupsd in tests/integration/print_card_test.cpp).
TEST(CheckCli, PrintQueueWithoutCupsFails) {
    const fs::path dir = scratchDir("check_print");
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[print]\nenabled = true\nqueue = \"photo\"\n";
    setenv("CUPS_SERVER", (dir / "no-cupsd.sock").c_str(), 1);  // whatever this machine runs
    const CommandResult json = run("check --json --config " + config.string(), dir);
    unsetenv("CUPS_SERVER");
    const nlohmann::json report = nlohmann::json::parse(json.output);
    EXPECT_NE(json.exitCode, 0);
    EXPECT_EQ(statusesOf(report, "print"), std::vector<std::string>{"FAIL"}) << messagesOf(report, "print");
    EXPECT_NE(messagesOf(report, "print").find("queue photo: no CUPS scheduler"), std::string::npos)
        << messagesOf(report, "print");
}

TEST(CheckCli, MissingHardwareTheConfigAsksForFails) {
    const fs::path dir = scratchDir("check_missing");
    const fs::path config = dir / "booth.toml";
    // Names no machine has: a V4L2 node, a GPIO chip, a DRM card.
    std::ofstream(config) << "[camera]\nbackend = \"v4l2\"\ndevice = \"/dev/video-avatarbooth-none\"\n"
                          << "[buttons]\nbackend = \"gpiod\"\nchip = \"avatarbooth-no-such-chip\"\n"
                          << "[display]\nbackend = \"kms\"\ndrm_device = \"/dev/dri/card-avatarbooth-none\"\n"
                          << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n";
    const CommandResult r = run("check --json --config " + config.string(), dir);
    EXPECT_EQ(r.exitCode, 8) << r.output << r.errors;  // kExitDevice
    const nlohmann::json report = nlohmann::json::parse(r.output);
    EXPECT_FALSE(report.at("ok").get<bool>());
    EXPECT_EQ(statusesOf(report, "camera").back(), "FAIL") << messagesOf(report, "camera");
    EXPECT_NE(messagesOf(report, "camera").find("/dev/video-avatarbooth-none not found"), std::string::npos);
    EXPECT_EQ(statusesOf(report, "gpio").back(), "FAIL") << messagesOf(report, "gpio");
    EXPECT_NE(messagesOf(report, "gpio").find("avatarbooth-no-such-chip"), std::string::npos);
    EXPECT_EQ(statusesOf(report, "display").back(), "FAIL") << messagesOf(report, "display");
    // A sessions folder that does not exist yet but can be made is fine.
    EXPECT_EQ(statusesOf(report, "sessions").back(), "OK") << messagesOf(report, "sessions");
    EXPECT_NE(messagesOf(report, "sessions").find("will be created"), std::string::npos);
}

TEST(CheckCli, AutoWithoutHardwareWarnsAndSaysNoneFound) {
    const fs::path dir = scratchDir("check_auto");
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[buttons]\nchip = \"avatarbooth-no-such-chip\"\n"
                          << "[display]\ndrm_device = \"/dev/dri/card-avatarbooth-none\"\n"
                          << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n";
    const CommandResult r = run("check --json --config " + config.string(), dir);
    const nlohmann::json report = nlohmann::json::parse(r.output);
    // "auto" falls back to the simulation: a warning, not a failure.
    EXPECT_EQ(statusesOf(report, "gpio").back(), "WARN") << messagesOf(report, "gpio");
    EXPECT_NE(messagesOf(report, "gpio").find("simulated buttons"), std::string::npos);
    EXPECT_EQ(statusesOf(report, "display").back(), "WARN") << messagesOf(report, "display");
    EXPECT_NE(messagesOf(report, "display").find("headless"), std::string::npos);
    EXPECT_EQ(r.exitCode, report.at("failures").get<int>() == 0 ? 0 : 8) << r.output;
}

TEST(CheckCli, BrokenConfigFailsNamingFileLineAndKey) {
    const fs::path dir = scratchDir("check_broken");
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[camera]\nbackend = \"sim\"\n\n[sessions]\nphoto_retention_hourz = 3\n";
    const CommandResult r = run("check --config " + config.string(), dir);
    EXPECT_EQ(r.exitCode, 6) << r.output << r.errors;  // kExitBadConfig
    EXPECT_NE(r.output.find("FAIL config    " + config.string() + ":5"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("photo_retention_hourz"), std::string::npos) << r.output;
    // The other checks still ran (with the defaults).
    EXPECT_NE(r.output.find("landmarks"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("sessions"), std::string::npos) << r.output;
}

TEST(CheckCli, MissingLandmarkModelFails) {
    const fs::path dir = scratchDir("check_model");
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[fit]\nlandmark_model = \"" << (dir / "none.dat").string() << "\"\n"
                          << "[camera]\nbackend = \"sim\"\n[buttons]\nbackend = \"sim\"\n[display]\nbackend = \"headless\"\n"
                          << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n";
    // A file that exists but is no model: found, and then refused when loaded.
    const fs::path junk = dir / "junk.dat";
    std::ofstream(junk) << "not a dlib model";
    CommandResult r = run("check --config " + config.string(), dir);
    EXPECT_EQ(r.exitCode, 6) << r.output;
    EXPECT_NE(r.output.find("FAIL landmarks " + (dir / "none.dat").string() + " not found"), std::string::npos) << r.output;

    std::ofstream(config) << "[fit]\nlandmark_model = \"" << junk.string() << "\"\n"
                          << "[camera]\nbackend = \"sim\"\n[buttons]\nbackend = \"sim\"\n[display]\nbackend = \"headless\"\n"
                          << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n";
    r = run("check --config " + config.string(), dir);
    EXPECT_EQ(r.exitCode, 6) << r.output;
    EXPECT_NE(r.output.find("FAIL landmarks cannot load"), std::string::npos) << r.output;
}
