// The daemon (`avatarbooth run` as a child process, the simulated booth) is killed with SIGKILL at random points
// while it fits and writes sessions and just after keeps (while the toon strip is added to the kept session), and
// started again: every session folder present is complete (its glb valid, its toon strip whole or absent),
// the sessions kept before are untouched, the next start removes what the killed one left, and the restarted booth
// tells systemd READY=1 (attract screen up) within 2 s.
#include "reliability_support.h"

#include "test_paths.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <random>
#include <thread>

namespace fs = std::filesystem;
using namespace avatarbooth;
using namespace avatarbooth::reliability;
using Seconds = std::chrono::duration<double>;

namespace {

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// The systemd notification socket the daemon's sd_notify() writes to (NOTIFY_SOCKET).
class NotifySocket {
public:
    explicit NotifySocket(const fs::path& path) : path_(path) {
        fs::remove(path_);
        fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        sockaddr_un addr{};
        addr.sun_family = AF_UNIX;
        std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path_.c_str());
        if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) ADD_FAILURE() << "bind " << path_;
    }
    ~NotifySocket() { ::close(fd_); }
    const fs::path& path() const { return path_; }
    // Reads and drops what has come (the booth pings WATCHDOG=1 every second): a socket nobody reads fills up, and
    // the booth's next sd_notify then blocks (it hung in STOPPING=1 at the end of this test once).
    void drain() {
        char buf[4096];
        while (::recv(fd_, buf, sizeof buf, MSG_DONTWAIT) > 0) {
        }
    }
    // Waits for a datagram holding READY=1; false on timeout.
    bool waitReady(std::chrono::milliseconds timeout) {
        const auto end = std::chrono::steady_clock::now() + timeout;
        while (std::chrono::steady_clock::now() < end) {
            pollfd p{fd_, POLLIN, 0};
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now()).count();
            if (::poll(&p, 1, static_cast<int>(std::max<long>(1, left))) <= 0) continue;
            char buf[4096];
            const ssize_t n = ::recv(fd_, buf, sizeof buf - 1, 0);
            if (n > 0 && std::string(buf, static_cast<std::size_t>(n)).find("READY=1") != std::string::npos) return true;
        }
        return false;
    }

private:
    fs::path path_;
    int fd_ = -1;
};

struct Daemon {
    pid_t pid = -1;
    std::chrono::steady_clock::time_point started;
};

Daemon spawnDaemon(const fs::path& config, const fs::path& log, const NotifySocket& notify) {
    Daemon d;
    d.started = std::chrono::steady_clock::now();
    d.pid = ::fork();
    if (d.pid == 0) {
        const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0600);
        ::dup2(fd, 1);
        ::dup2(fd, 2);
        ::setenv("NOTIFY_SOCKET", notify.path().c_str(), 1);
        ::setenv("EGL_PLATFORM", "surfaceless", 1);
        const std::string bin = test::binary().string();
        const std::string cfg = config.string();
        ::execl(bin.c_str(), bin.c_str(), "run", "--config", cfg.c_str(), "--sessions", "100", static_cast<char*>(nullptr));
        ::_exit(127);
    }
    return d;
}

// A folder being staged under .pending/ (the fit is writing its files).
bool writingNow(const fs::path& sessions) {
    std::error_code ec;
    for (auto it = fs::directory_iterator(sessions / ".pending", ec); !ec && it != fs::directory_iterator(); it.increment(ec))
        if (it->path().filename().string().find(".partial-") != std::string::npos) return true;
    return false;
}

}  // namespace

TEST(DaemonKill, KilledWhileWritingLeavesOnlyCompleteSessionsAndRestartsFast) {
    const fs::path dir = test::scratchDir("reliability_daemon_kill");
    const fs::path sessions = dir / "sessions";
    const fs::path visitor = syntheticVisitorFolder(fs::path(AVATARBOOTH_TEST_WORK_DIR) / "reliability_visitor");
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[camera]\nbackend = \"sim\"\nsim_folder = \"" << visitor.string() << "\"\n"
                          << "[buttons]\nbackend = \"sim\"\n"
                          << "[display]\nbackend = \"headless\"\nwidth = 640\nheight = 360\n"
                          << "[screen]\nstrings_file = \"" << AVATARBOOTH_TEST_SOURCE_DIR << "/app/assets/strings.toml\"\n"
                          << "[flow]\ncountdown_s = 1.0\nsteady_s = 0.0\nthanks_time_s = 1.0\nthanks_min_time_s = 0.0\n"
                          << "press_guard_s = 0.1\n"
                          << "[sessions]\ndirectory = \"" << sessions.string() << "\"\n";
    NotifySocket notify(dir / "notify.sock");
    const fs::path log = dir / "daemon.log";
    std::mt19937 rng(20261122);

    std::map<std::string, std::map<std::string, std::uint64_t>> kept;  // code -> fingerprint, as first seen
    std::vector<double> readySeconds;
    const int kills = 6;
    std::size_t fitsSeen = 0;
    Daemon d = spawnDaemon(config, log, notify);
    ASSERT_TRUE(notify.waitReady(std::chrono::seconds(30))) << test::readFileBytes(log);
    std::size_t keepsSeen = 0;
    for (int k = 0; k < kills; ++k) {
        // In turn: killed while the fit's files are being staged, at a random moment from the fit's start, or just
        // after a keep (while the kept session's toon is drawn and its strip written: the keep does not wait for it).
        enum class When { Staging, AfterFit, AfterKeep } when = static_cast<When>(k % 3);
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        bool due = false;
        while (std::chrono::steady_clock::now() < deadline && !due) {
            if (when == When::Staging) due = writingNow(sessions);
            else if (when == When::AfterFit) due = count(test::readFileBytes(log), "] fitting the photos") > fitsSeen;
            else due = count(test::readFileBytes(log), "session kept as") > keepsSeen;
            notify.drain();
            if (!due) std::this_thread::sleep_for(std::chrono::milliseconds(when == When::Staging ? 1 : 20));
        }
        if (!due) {  // never leave the daemon running behind a failed test
            ::kill(d.pid, SIGKILL);
            ::waitpid(d.pid, nullptr, 0);
        }
        ASSERT_TRUE(due) << "no fit or keep seen in 60 s: " << test::readFileBytes(log);
        fitsSeen = count(test::readFileBytes(log), "] fitting the photos");
        keepsSeen = count(test::readFileBytes(log), "session kept as");
        const int maxDelayMs = when == When::Staging ? 120 : when == When::AfterFit ? 2500 : 1500;
        const int delayMs = std::uniform_int_distribution<int>(0, maxDelayMs)(rng);
        std::this_thread::sleep_for(std::chrono::milliseconds(delayMs));
        ::kill(d.pid, SIGKILL);
        int status = 0;
        ::waitpid(d.pid, &status, 0);
        ASSERT_TRUE(WIFSIGNALED(status));

        // What the killed booth left: complete sessions only (pending ones are hidden and removed at restart; a
        // kept session's toon strip is whole, absent, or still in its staging folder, a leftover).
        const SessionsCheck after = checkSessions(sessions);
        int withToon = 0;
        for (const auto& code : after.complete) withToon += fs::exists(sessions / code / "toon") ? 1 : 0;
        std::printf("figure: kill %d %s +%d ms: %zu sessions complete (%d with their toon strip), %d leftovers\n", k + 1,
                    when == When::Staging ? "while staging files" : when == When::AfterFit ? "after the fit started"
                                                                                          : "after a keep",
                    delayMs, after.complete.size(), withToon, after.leftovers);
        for (const auto& p : after.problems) ADD_FAILURE() << "after kill " << k + 1 << ": " << p;
        for (auto& [code, print] : kept) {
            const auto now = fingerprint(sessions / code);
            EXPECT_EQ(changesSince(print, now), std::vector<std::string>{}) << code << " changed";
            print = now;  // a toon strip that has appeared since must stay as it is from now on
        }
        for (const auto& code : after.complete)
            if (!kept.count(code)) kept[code] = fingerprint(sessions / code);

        d = spawnDaemon(config, log, notify);
        if (!notify.waitReady(std::chrono::seconds(30))) {
            ::kill(d.pid, SIGKILL);
            ::waitpid(d.pid, nullptr, 0);
            FAIL() << "no READY=1 within 30 s of the restart: " << test::readFileBytes(log);
        }
        readySeconds.push_back(Seconds(std::chrono::steady_clock::now() - d.started).count());
        EXPECT_EQ(checkSessions(sessions).leftovers, 0) << "the restarted booth did not clear the killed one's leftovers";
    }
    // The last one ends normally once it has kept a session.
    const std::size_t keptBefore = count(test::readFileBytes(log), "session kept as");
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(90);
    while (std::chrono::steady_clock::now() < deadline && count(test::readFileBytes(log), "session kept as") == keptBefore) {
        notify.drain();
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    notify.drain();
    ::kill(d.pid, SIGTERM);
    int status = 0;
    ::waitpid(d.pid, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;

    const SessionsCheck last = checkSessions(sessions);
    for (const auto& p : last.problems) ADD_FAILURE() << p;
    EXPECT_EQ(last.leftovers, 0);
    EXPECT_GE(last.complete.size(), 1u);
    for (const auto& [code, print] : kept)
        EXPECT_EQ(changesSince(print, fingerprint(sessions / code)), std::vector<std::string>{}) << code << " changed";
    if (haveGltfValidator()) {
        for (const auto& code : last.complete) {
            std::string report;
            EXPECT_TRUE(validateGlb(sessions / code / "avatar.glb", &report)) << code << ": " << report;
        }
    }
    double worst = 0.0;
    for (double s : readySeconds) worst = std::max(worst, s);
    std::printf("figure: %d SIGKILLs, %zu sessions complete, restart to READY=1 worst %.2f s\n", kills,
                last.complete.size(), worst);
    EXPECT_LT(worst, recoveryBoundSeconds());
}
