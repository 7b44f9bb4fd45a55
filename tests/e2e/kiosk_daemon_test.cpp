// `avatarbooth run` as systemd runs it, while the landmark model never finishes loading (it is read from a named
// pipe nobody writes to: dlib's deserialisation blocks in read(), as a slow load does): READY comes anyway, a press
// reaches the front guide, which says "no face" from the face cascade alone, the watchdog pings keep their
// interval (half of WATCHDOG_USEC) on our own NOTIFY_SOCKET, and SIGTERM ends it within 2 s with exit code 0.
#include "kiosk_daemon_checks.h"
#include "process_sockets.h"
#include "test_paths.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using avatarbooth::Hint;
using avatarbooth::ScreenId;
using namespace avatarbooth::test;

namespace {

// Polls (draining the notify socket as it goes) until `done` or the time is up or the child has exited.
template <typename F>
bool waitFor(F done, std::chrono::steady_clock::duration limit, NotifySocket& notify, pid_t pid, int& status,
             bool& exited) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
        notify.drain();
        if (done()) return true;
        if (!exited && waitpid(pid, &status, WNOHANG) == pid) exited = true;
        if (exited) return done();
        std::this_thread::sleep_for(20ms);
    }
    return done();
}

}  // namespace

TEST(KioskDaemon, GuideSaysNoFaceKeepsPingingAndStopsPromptlyWhileTheModelIsStillLoading) {
    const fs::path dir = scratchDir("kiosk_daemon");
    // The model: a named pipe. The test holds it open for writing (O_RDWR: no wait for a reader) and never writes,
    // so the booth's load blocks in read() for as long as the booth runs.
    const fs::path model = dir / "model.fifo";
    ASSERT_EQ(mkfifo(model.c_str(), 0600), 0) << std::strerror(errno);
    const int writer = open(model.c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(writer, 0) << std::strerror(errno);
    std::ofstream(dir / "buttons.txt") << "at 2500ms tap start\n";
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[fit]\nlandmark_model = \"" << model.string() << "\"\n"
                          << "[camera]\nbackend = \"sim\"\n"
                          << "[buttons]\nbackend = \"sim\"\ntimeline = \"" << (dir / "buttons.txt").string() << "\"\n"
                          << "[display]\nbackend = \"headless\"\n"
                          << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n";

    NotifySocket notify("daemon");
    ASSERT_TRUE(notify.ok()) << std::strerror(errno);
    const fs::path log = dir / "log.txt", screens = dir / "screens";
    constexpr int kWatchdogUsec = 1200000;  // WatchdogSec=1.2s: a ping every 600 ms
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        setenv("NOTIFY_SOCKET", notify.env().c_str(), 1);
        setenv("WATCHDOG_USEC", std::to_string(kWatchdogUsec).c_str(), 1);
        unsetenv("WATCHDOG_PID");
        const int out = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(out, 1);
        dup2(out, 2);
        const std::string bin = binary().string();
        execl(bin.c_str(), bin.c_str(), "run", "--config", config.c_str(), "--visitor", "no", "--screenshots",
              screens.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    int status = 0;
    bool exited = false;
    const auto kill9 = [&] {
        if (!exited) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            exited = true;
        }
        close(writer);
    };

    // READY before the model: the attract screen runs while the load is stuck. (The first run in a folder makes the
    // synthetic visitor the sim camera shows first: seconds, more on a busy machine.)
    const bool ready = waitFor([&] { return !notify.ready.empty(); }, 90s, notify, pid, status, exited);
    if (!ready) kill9();
    ASSERT_TRUE(ready) << "no READY=1\n" << readFileBytes(log);
    const bool guide = waitFor([&] { return fs::exists(screens / "01_front_guide.png"); }, 30s, notify, pid, status,
                               exited);
    if (!guide) kill9();
    ASSERT_TRUE(guide) << "no front guide screenshot\n" << readFileBytes(log);
    // The first analysis's hint (the screenshot is taken again with it when it came later than the picture).
    waitFor([&] { return readFileBytes(log).find("front_guide: hint no_face") != std::string::npos; }, 30s, notify, pid,
            status, exited);

    // In the guide: pings every 600 ms for 3 s (no gap as long as the 1.2 s the watchdog allows).
    const auto from = std::chrono::steady_clock::now();
    waitFor([] { return false; }, 3s, notify, pid, status, exited);
    const auto to = std::chrono::steady_clock::now();
    EXPECT_FALSE(exited) << readFileBytes(log);
    EXPECT_GE(notify.pingsSince(from), 4) << "3 s in the guide";
    EXPECT_LE(notify.pingsSince(from), 6) << "pings faster than half of WATCHDOG_USEC";
    EXPECT_LT(notify.longestGapSeconds(from, to), kWatchdogUsec / 1e6) << "a watchdog ping came late";
    // [share] and [print] at their defaults: the running kiosk holds no TCP listening or bound UDP socket.
    EXPECT_EQ(listeningSockets(pid), std::vector<std::string>{}) << "the kiosk listens on the network";

    // SIGTERM while the model is still loading: gone within 2 s, exit code 0.
    const auto term = std::chrono::steady_clock::now();
    kill(pid, SIGTERM);
    waitFor([&] { return exited; }, 2s, notify, pid, status, exited);
    const double stopSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - term).count();
    const bool stopped = exited;
    kill9();
    const std::string output = readFileBytes(log);
    ASSERT_TRUE(stopped) << "still running 2 s after SIGTERM\n" << output;
    EXPECT_LT(stopSeconds, 2.0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status << "\n" << output;
    EXPECT_EQ(output.find("landmark model loaded"), std::string::npos) << output;
    EXPECT_NE(output.find("still loading"), std::string::npos) << output;
    EXPECT_NE(output.find("front_guide: hint no_face"), std::string::npos) << output;

    // The guide's screenshot (taken once its first hint is known) shows the "no face" hint, not the initial one.
    const cv::Mat shot = cv::imread((screens / "01_front_guide.png").string());
    ASSERT_FALSE(shot.empty());
    EXPECT_GT(guideHintMatch(shot, ScreenId::FrontGuide, Hint::NoFace), 0.8);
    EXPECT_LT(guideHintMatch(shot, ScreenId::FrontGuide, Hint::None), 0.5);
    EXPECT_FALSE(fs::exists(screens / "02_countdown.png")) << "counted down without a face";
}
