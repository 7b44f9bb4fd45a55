// Issue 23 end to end: a visitor fitted by `avatarbooth fit` and kept by the session store; the thanks screen with
// its QR code, read back with `zbarimg` (Debian zbar-tools) as a phone's camera would; `avatarbooth share` serving
// the sessions folder; headless Chromium (tests/browser/check_share_page.mjs, puppeteer-core) opening that URL as a
// phone, which must see the avatar drawn by <model-viewer> with its AR button's glb and usdz, no console error
// (CSP included), nothing fetched from elsewhere. (The kiosk's own thanks screenshot carries the same QR code:
// KioskSim.OneScriptedSessionEndToEnd reads it; a whole kiosk session here would cost another 35 s.)
#include "run_binary.h"

#include "booth/screens/screens.h"
#include "booth/session_store.h"
#include "booth/share_link.h"

#include <opencv2/imgcodecs.hpp>

#include <gtest/gtest.h>

#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;
using namespace avatarbooth::test;
using namespace std::chrono_literals;

namespace {

// A loopback port nobody listens on now (bound to port 0, read back, closed).
int freePort() {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
    socklen_t len = sizeof a;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    ::close(fd);
    return ntohs(a.sin_port);
}

}  // namespace

TEST(SharePage, QrCodeOpensTheAvatarPageInChromium) {
    for (const char* tool : {"zbarimg", "node", "/usr/bin/chromium"})
        if (runShell(std::string("command -v ") + tool + " 2>&1").exitCode != 0) GTEST_SKIP() << tool << " is not installed";
    const fs::path browser = fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "tests/browser";
    if (!fs::is_directory(browser / "node_modules/puppeteer-core")) GTEST_SKIP() << "puppeteer-core (npm) is not installed";

    const fs::path dir = scratchDir("share_page");
    const int port = freePort();
    const std::string base = "http://127.0.0.1:" + std::to_string(port);
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n"
                          << "[share]\nenabled = true\nlisten = \"127.0.0.1:" << port << "\"\n";
    // A visitor fitted and kept as the kiosk keeps one.
    avatarbooth::SessionStoreSettings sessions;
    sessions.directory = dir / "sessions";
    avatarbooth::SessionStore store(sessions);
    const fs::path pending = store.pendingPath();
    ASSERT_EQ(runAvatarbooth("make-visitor --seed 2 -o " + (dir / "visitor").string()).exitCode, 0);
    const CommandResult fit = runAvatarbooth("fit --front " + (dir / "visitor/front.jpg").string() + " --side " +
                                             (dir / "visitor/side.jpg").string() + " -o " + pending.string());
    ASSERT_EQ(fit.exitCode, 0) << fit.output;
    const std::string code = store.keep(pending, std::chrono::system_clock::now());
    const fs::path session = *store.find(code);
    EXPECT_TRUE(fs::is_regular_file(session / "avatar.usdz"));

    // The thanks screen for it, and its QR code as a phone's camera reads it.
    avatarbooth::ShareSettings share;
    share.enabled = true;
    share.listen = "127.0.0.1:" + std::to_string(port);
    avatarbooth::ScreenRenderer screens(avatarbooth::ScreenSettings{});
    avatarbooth::ScreenModel thanks;
    thanks.id = avatarbooth::ScreenId::Thanks;
    thanks.code = code;
    thanks.shareUrl = avatarbooth::sharePageUrl(share, avatarbooth::readShareToken(session).value_or(""));
    cv::imwrite((dir / "thanks.png").string(), screens.draw(thanks, {}));
    // (zbarimg's complaints about a missing D-Bus go to stderr: not part of the URL.)
    const CommandResult qr = runShell("(zbarimg --raw -q " + (dir / "thanks.png").string() + " 2>/dev/null) 2>&1");
    ASSERT_EQ(qr.exitCode, 0) << qr.output;
    const std::string url = std::regex_replace(qr.output, std::regex("\\s+$"), "");
    ASSERT_TRUE(std::regex_match(url, std::regex(base + "/s/[0-9a-f]{32}"))) << url;

    // The page server on that sessions folder, as the unit starts it.
    const fs::path log = dir / "share.log";
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        const int out = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(out, 1);
        dup2(out, 2);
        const std::string bin = binary().string();
        execl(bin.c_str(), bin.c_str(), "share", "--config", config.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    for (int i = 0; i < 250 && readFileBytes(log).find("listening on") == std::string::npos; ++i) std::this_thread::sleep_for(20ms);
    const CommandResult page = runShell("cd " + browser.string() + " && node check_share_page.mjs '" + url + "' " +
                                        (dir / "page.png").string() + " 2>&1");
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    std::printf("[ figures ] the page in Chromium (loopback, 390x844 phone): %s\n", page.output.c_str());
    EXPECT_EQ(page.exitCode, 0) << page.output << readFileBytes(log);
    EXPECT_NE(page.output.find("\"ok\":true"), std::string::npos) << page.output;
}
