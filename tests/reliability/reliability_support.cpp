// The reliability suite's shared helpers: the fast booth configuration and the sessions-folder checks.
#include "reliability_support.h"

#include "sim/synthetic_visitor.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <thread>

namespace avatarbooth::reliability {
namespace fs = std::filesystem;

BoothConfig fastSimBooth(const fs::path& visitorFolder, const fs::path& sessions) {
    BoothConfig c;
    c.camera.backend = "sim";
    c.camera.simFolder = visitorFolder.string();
    c.camera.simRealTime = true;
    // A camera that comes back is found again within a second (the reopen back-off is capped here).
    c.camera.reopenFirstDelaySeconds = 0.2;
    c.camera.reopenMaxDelaySeconds = 1.0;
    c.buttons.backend = "sim";
    c.display.backend = "headless";
    c.display.width = 640;
    c.display.height = 360;
    c.sessions.directory = sessions;
    // The source tree's strings (the test executables do not sit where the installed booth looks).
    c.screen.stringsFile = fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "app" / "assets" / "strings.toml";
    c.stage.map = fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "app" / "assets" / "stage.map";
    // All three styles, as a booth runs them: a keep no longer waits for the toon (its strip is added to the kept
    // session once drawn), so the toon's drawing time does not stretch these shortened waits.
    c.reveal.styles = {AvatarStyle::Photo, AvatarStyle::Character, AvatarStyle::Toon};
    BoothSettings& f = c.flow;
    f.countdown = Millis(300);
    f.steadyOk = Millis(200);
    f.guideAbsentTimeout = Millis(1200);
    f.guideMaxTime = Millis(30000);
    f.captureTimeout = Millis(5000);
    f.processingTimeout = Millis(60000);
    f.revealTimeout = Millis(1500);
    f.retakeChoiceTimeout = Millis(5000);
    f.thanksTime = Millis(400);
    f.thanksMinTime = Millis(0);
    f.cameraLostTimeout = Millis(8000);
    f.pressGuard = Millis(100);
    return c;
}

fs::path syntheticVisitorFolder(const fs::path& dir) { return ensureSyntheticVisitorFolder(dir / "synthetic-visitor"); }

const std::vector<std::string>& sessionFiles() {
    static const std::vector<std::string> files = {"avatar.glb",     "fit.json",  "landmarks.json", "session.json",
                                                   "front.jpg",      "side.jpg",  "preview_front.png"};
    return files;
}

namespace {

std::string readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::uint32_t le32(const std::string& b, std::size_t at) {
    return static_cast<std::uint32_t>(static_cast<unsigned char>(b[at])) |
           static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 1])) << 8 |
           static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 2])) << 16 |
           static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 3])) << 24;
}

bool isPng(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    char sig[8] = {};
    return in.read(sig, 8) && std::string(sig, 8) == "\x89PNG\r\n\x1a\n";
}

// The toon strip a kept session gets after the keep: absent, or whole (turntable_000.png .. turntable_NNN.png, every
// one a PNG, nothing else). It is staged beside the session as ".toon.partial-*" and renamed into place, so a kill
// can leave the staging folder (a leftover, see partialEntries) but never a toon/ with frames missing.
std::string toonProblem(const fs::path& toon) {
    std::error_code ec;
    if (!fs::exists(toon, ec)) return {};
    if (!fs::is_directory(toon, ec)) return "toon is not a folder";
    std::size_t frames = 0;
    for (const auto& e : fs::directory_iterator(toon)) {
        const std::string name = e.path().filename().string();
        if (name.size() != 17 || name.rfind("turntable_", 0) != 0 || name.compare(13, 4, ".png") != 0 ||
            name.find_first_not_of("0123456789", 10) != 13)
            return "toon/ holds " + name + " (only turntable_NNN.png belong there)";
        if (!e.is_regular_file(ec) || !isPng(e.path())) return "toon/" + name + " is not a PNG";
        ++frames;
    }
    for (std::size_t i = 0; i < frames; ++i) {
        char name[48];
        std::snprintf(name, sizeof name, "turntable_%03zu.png", i);
        if (!fs::exists(toon / name, ec)) return "toon/ has " + std::to_string(frames) + " frames but no " + name;
    }
    if (frames == 0) return "toon/ is empty";
    return {};
}

// A session's half-written late addition (the toon strip's staging folder ".toon.partial-*"): a leftover that the
// next start removes (SessionStore::removeLeftovers), not part of the session.
int partialEntries(const fs::path& folder) {
    int n = 0;
    std::error_code ec;
    for (auto it = fs::directory_iterator(folder, ec); !ec && it != fs::directory_iterator(); it.increment(ec))
        if (it->path().filename().string().find(".partial-") != std::string::npos) ++n;
    return n;
}

// Empty when the folder is a complete session, else what is wrong.
std::string sessionProblem(const fs::path& folder) {
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) return "is not a folder";
    for (const auto& name : sessionFiles()) {
        if (!fs::is_regular_file(folder / name, ec)) return "has no " + name;
        if (fs::file_size(folder / name, ec) == 0) return name + " is empty";
    }
    for (const auto& e : fs::directory_iterator(folder))
        if (e.path().filename().string().find(".tmp-") != std::string::npos)
            return "holds a temporary file " + e.path().filename().string();
    if (const std::string toon = toonProblem(folder / "toon"); !toon.empty()) return toon;
    for (const char* json : {"fit.json", "session.json", "landmarks.json"})
        if (nlohmann::json::parse(readAll(folder / json), nullptr, false).is_discarded()) return std::string(json) + " does not parse";
    const std::string glb = readAll(folder / "avatar.glb");
    if (glb.size() < 20 || glb.compare(0, 4, "glTF") != 0 || le32(glb, 4) != 2 || le32(glb, 8) != glb.size())
        return "avatar.glb has a wrong GLB header or length";
    return {};
}

}  // namespace

SessionsCheck checkSessions(const fs::path& sessions) {
    SessionsCheck check;
    std::error_code ec;
    if (!fs::is_directory(sessions, ec)) return check;
    for (const auto& e : fs::directory_iterator(sessions)) {
        const std::string name = e.path().filename().string();
        if (name == ".pending") {
            for (auto it = fs::directory_iterator(e.path(), ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
                ++check.leftovers;
                check.leftoverNames.push_back(".pending/" + it->path().filename().string());
            }
            continue;
        }
        if (name.rfind(".trash-", 0) == 0) {
            ++check.leftovers;
            check.leftoverNames.push_back(name);
            continue;
        }
        check.leftovers += partialEntries(e.path());
        if (fs::exists(e.path() / "toon", ec)) ++check.withToon;
        const std::string problem = sessionProblem(e.path());
        if (problem.empty()) check.complete.push_back(name);
        else check.problems.push_back(name + ": " + problem);
    }
    return check;
}

bool haveGltfValidator() {
    return fs::exists(fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "tests" / "gltf" / "node_modules" / "gltf-validator");
}

bool validateGlb(const fs::path& glb, std::string* report) {
    const fs::path validator = fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "tests" / "gltf" / "validate.mjs";
    const std::string cmd = "node '" + validator.string() + "' '" + glb.string() + "' 2>&1";
    FILE* pipe = popen(cmd.c_str(), "r");
    if (!pipe) return false;
    std::string out;
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), static_cast<int>(buf.size()), pipe)) out += buf.data();
    const bool ok = pclose(pipe) == 0 && out.find("\"errors\":0") != std::string::npos;
    if (report) *report = out;
    return ok;
}

std::map<std::string, std::uint64_t> fingerprint(const fs::path& folder) {
    std::map<std::string, std::uint64_t> out;
    for (auto it = fs::recursive_directory_iterator(folder); it != fs::recursive_directory_iterator(); ++it) {
        const auto& e = *it;
        if (e.path().filename().string().find(".partial-") != std::string::npos) {  // a leftover, not the session's
            if (e.is_directory()) it.disable_recursion_pending();
            continue;
        }
        if (!e.is_regular_file()) continue;
        std::uint64_t h = 1469598103934665603ull;
        for (const char c : readAll(e.path())) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
        out[fs::relative(e.path(), folder).string()] = h;
    }
    return out;
}

std::vector<std::string> changesSince(const std::map<std::string, std::uint64_t>& before,
                                      const std::map<std::string, std::uint64_t>& now) {
    std::vector<std::string> changes;
    const bool toonBefore = std::any_of(before.begin(), before.end(), [](const auto& f) { return f.first.rfind("toon/", 0) == 0; });
    for (const auto& [name, hash] : before) {
        const auto it = now.find(name);
        if (it == now.end()) changes.push_back(name + " is gone");
        else if (it->second != hash) changes.push_back(name + " changed");
    }
    for (const auto& [name, hash] : now)
        if (!before.count(name) && (toonBefore || name.rfind("toon/", 0) != 0)) changes.push_back(name + " appeared");
    return changes;
}

double recoveryBoundSeconds() {
    double load[1] = {0.0};
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    if (getloadavg(load, 1) == 1 && load[0] > cores) {
        std::printf("note: load average %.1f on %u cores: the 2 s recovery bound is relaxed to 10 s\n", load[0], cores);
        return 10.0;
    }
    return 2.0;
}

}  // namespace avatarbooth::reliability
