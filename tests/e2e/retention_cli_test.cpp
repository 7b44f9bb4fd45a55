// Retention as the installed booth applies it: `avatarbooth retention` (what avatarbooth-retention.timer runs) with
// the ages from a config file deletes the photos of sessions kept longer ago than photo_retention_hours and whole
// sessions older than session_retention_days, and leaves newer sessions and a fit in progress alone.
#include "run_binary.h"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <chrono>
#include <fstream>

namespace fs = std::filesystem;
using namespace avatarbooth::test;

namespace {


// A kept session as SessionStore::keep leaves it, kept `age` ago.
void makeSession(const fs::path& sessions, const std::string& code, std::chrono::seconds age) {
    const fs::path dir = sessions / code;
    fs::create_directories(dir);
    const auto kept = std::chrono::duration_cast<std::chrono::seconds>(
                          (std::chrono::system_clock::now() - age).time_since_epoch()).count();
    std::ofstream(dir / "session.json") << "{\"code\": \"" << code << "\", \"kept_at\": " << kept << "}";
    for (const char* f : {"front.jpg", "side.jpg", "front_overlay.jpg", "avatar.glb", "fit.json", "preview_front.png"})
        std::ofstream(dir / f) << "data of " << f;
}

}  // namespace

TEST(RetentionCli, DeletesPhotosFirstThenWholeSessionsByTheConfiguredAges) {
    const fs::path dir = scratchDir("retention_cli");
    const fs::path sessions = dir / "sessions";
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[sessions]\ndirectory = \"" << sessions.string() << "\"\n"
                          << "photo_retention_hours = 1.0\nsession_retention_days = 2.0\n";
    using std::chrono::hours;
    makeSession(sessions, "AAAAAA", hours(24 * 3));  // past both ages: the whole session goes
    makeSession(sessions, "BBBBBB", hours(2));       // past the photos' age: photos go, the avatar stays
    makeSession(sessions, "CCCCCC", std::chrono::minutes(10));  // new: untouched
    fs::create_directories(sessions / ".pending" / "fit-in-progress");
    std::ofstream(sessions / ".pending" / "fit-in-progress" / "front.jpg") << "a visitor at the booth now";

    const CommandResult r = runAvatarbooth("retention --config " + config.string());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("deleted 3 photo file(s) and 1 session(s)"), std::string::npos) << r.output;

    EXPECT_FALSE(fs::exists(sessions / "AAAAAA"));
    for (const char* f : {"front.jpg", "side.jpg", "front_overlay.jpg"}) EXPECT_FALSE(fs::exists(sessions / "BBBBBB" / f)) << f;
    for (const char* f : {"avatar.glb", "fit.json", "preview_front.png", "session.json"})
        EXPECT_TRUE(fs::exists(sessions / "BBBBBB" / f)) << f;
    for (const char* f : {"front.jpg", "side.jpg", "avatar.glb"}) EXPECT_TRUE(fs::exists(sessions / "CCCCCC" / f)) << f;
    EXPECT_TRUE(fs::exists(sessions / ".pending" / "fit-in-progress" / "front.jpg"));
    // Nothing half-deleted is left behind.
    for (const auto& e : fs::directory_iterator(sessions))
        EXPECT_NE(e.path().filename().string().rfind(".trash-", 0), 0u) << e.path();

    // Run again: nothing more to do.
    const CommandResult again = runAvatarbooth("retention --config " + config.string());
    EXPECT_NE(again.output.find("deleted 0 photo file(s) and 0 session(s)"), std::string::npos) << again.output;
}
