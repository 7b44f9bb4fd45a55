// The development window under Xvfb: `avatarbooth run` with the window display draws its frames into an X11
// window (read back with XGetImage) and the keyboard presses the booth's buttons (keys sent to the window).
#include "run_binary.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

// X11 last: its macros (None, Status, Bool) clash with other headers.
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/keysym.h>

namespace fs = std::filesystem;
using namespace avatarbooth::test;
using namespace std::chrono_literals;

namespace {

constexpr const char* kXvfb = "/usr/bin/Xvfb";
constexpr const char* kTitle = "avatarbooth-window-test";

// A child process, ended (SIGTERM, then SIGKILL) when the test leaves early.
struct Child {
    pid_t pid = -1;
    ~Child() {
        if (pid <= 0) return;
        kill(pid, SIGTERM);
        for (int i = 0; i < 50; ++i) {
            if (waitpid(pid, nullptr, WNOHANG) == pid) return;
            std::this_thread::sleep_for(100ms);
        }
        kill(pid, SIGKILL);
        waitpid(pid, nullptr, 0);
    }
    // Exit code after SIGTERM (-1 when it did not exit by itself within `wait`).
    int terminate(std::chrono::seconds wait) {
        kill(pid, SIGTERM);
        const auto until = std::chrono::steady_clock::now() + wait;
        int status = 0;
        while (std::chrono::steady_clock::now() < until) {
            if (waitpid(pid, &status, WNOHANG) == pid) {
                pid = -1;
                return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
            }
            std::this_thread::sleep_for(50ms);
        }
        return -1;
    }
};

// Starts Xvfb on a free display (it writes the display number to a pipe: -displayfd); returns ":N".
std::optional<std::string> startXvfb(Child& xvfb) {
    int fds[2];
    if (pipe(fds) != 0) return std::nullopt;
    xvfb.pid = fork();
    if (xvfb.pid == 0) {
        close(fds[0]);
        const int devnull = open("/dev/null", O_WRONLY);
        dup2(devnull, STDOUT_FILENO);
        dup2(devnull, STDERR_FILENO);
        const std::string fd = std::to_string(fds[1]);
        execl(kXvfb, "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1280x720x24", "-nolisten", "tcp",
              static_cast<char*>(nullptr));
        _exit(127);
    }
    close(fds[1]);
    std::string number;
    pollfd p{fds[0], POLLIN, 0};
    const auto until = std::chrono::steady_clock::now() + 15s;
    while (std::chrono::steady_clock::now() < until && number.find('\n') == std::string::npos) {
        if (poll(&p, 1, 200) <= 0) continue;
        char c[16];
        const ssize_t n = read(fds[0], c, sizeof c);
        if (n <= 0) break;
        number.append(c, static_cast<std::size_t>(n));
    }
    close(fds[0]);
    if (number.find('\n') == std::string::npos) return std::nullopt;
    return ":" + number.substr(0, number.find('\n'));
}

Window findWindow(::Display* x, const char* title) {
    Window root = DefaultRootWindow(x), parent = 0, *children = nullptr;
    unsigned count = 0;
    Window found = 0;
    if (XQueryTree(x, root, &root, &parent, &children, &count) == 0) return 0;
    for (unsigned i = 0; i < count && found == 0; ++i) {
        char* name = nullptr;
        if (XFetchName(x, children[i], &name) != 0 && name != nullptr) {
            if (std::string(name) == title) found = children[i];
            XFree(name);
        }
    }
    if (children != nullptr) XFree(children);
    return found;
}

// The window's pixels as BGR (a 24-bit Xvfb screen: 32 bits per pixel, blue in the lowest byte).
cv::Mat grab(::Display* x, Window w) {
    XWindowAttributes attrs{};
    if (XGetWindowAttributes(x, w, &attrs) == 0 || attrs.width <= 0 || attrs.height <= 0) return {};
    XImage* image = XGetImage(x, w, 0, 0, static_cast<unsigned>(attrs.width), static_cast<unsigned>(attrs.height),
                              AllPlanes, ZPixmap);
    if (image == nullptr) return {};
    cv::Mat bgr(attrs.height, attrs.width, CV_8UC3);
    for (int y = 0; y < attrs.height; ++y)
        for (int xx = 0; xx < attrs.width; ++xx) {
            const unsigned long p = XGetPixel(image, xx, y);
            bgr.at<cv::Vec3b>(y, xx) = cv::Vec3b(static_cast<uchar>(p & 0xff), static_cast<uchar>((p >> 8) & 0xff),
                                                 static_cast<uchar>((p >> 16) & 0xff));
        }
    XDestroyImage(image);
    return bgr;
}

void sendKey(::Display* x, Window w, KeySym sym) {
    for (const int type : {KeyPress, KeyRelease}) {
        XEvent e{};
        e.xkey.type = type;
        e.xkey.display = x;
        e.xkey.window = w;
        e.xkey.root = DefaultRootWindow(x);
        e.xkey.subwindow = 0;
        e.xkey.time = CurrentTime;
        e.xkey.same_screen = True;
        e.xkey.keycode = XKeysymToKeycode(x, sym);
        XSendEvent(x, w, True, type == KeyPress ? KeyPressMask : KeyReleaseMask, &e);
        XFlush(x);
        std::this_thread::sleep_for(150ms);
    }
}

double differingShare(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    cv::Mat grey = diff.reshape(1, static_cast<int>(diff.total()));
    cv::Mat maxChannel;
    cv::reduce(grey, maxChannel, 1, cv::REDUCE_MAX);
    return static_cast<double>(cv::countNonZero(maxChannel > 40)) / static_cast<double>(a.total());
}

}  // namespace

TEST(KioskWindow, KeysPressButtonsAndFramesReachTheWindowUnderXvfb) {
    if (!fs::exists(kXvfb)) GTEST_SKIP() << kXvfb << " not found (Debian package xvfb; tests/setup.sh installs it)";
    Child xvfb;
    const auto display = startXvfb(xvfb);
    ASSERT_TRUE(display) << "Xvfb did not report a display";

    const fs::path dir = scratchDir("kiosk_window");
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[camera]\nbackend = \"sim\"\n[buttons]\nbackend = \"sim\"\n"
                          << "[display]\nbackend = \"window\"\nwindow_title = \"" << kTitle << "\"\n"
                          << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n";
    const fs::path log = dir / "run.log";
    Child kiosk;
    kiosk.pid = fork();
    if (kiosk.pid == 0) {
        setenv("DISPLAY", display->c_str(), 1);
        const int out = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
        dup2(out, STDOUT_FILENO);
        dup2(out, STDERR_FILENO);
        // No simulated visitor: the keyboard is the only way to press a button.
        execl(binary().c_str(), "avatarbooth", "run", "--config", config.c_str(), "--visitor", "no",
              static_cast<char*>(nullptr));
        _exit(127);
    }

    ::Display* x = XOpenDisplay(display->c_str());
    ASSERT_NE(x, nullptr) << "cannot open " << *display;
    // A window that goes away (the kiosk failing) must fail the test, not end it: Xlib's default handler exits.
    XSetErrorHandler([](::Display*, XErrorEvent*) { return 0; });
    Window w = 0;
    cv::Mat attract;
    for (auto until = std::chrono::steady_clock::now() + 60s; std::chrono::steady_clock::now() < until;) {
        if (w == 0) w = findWindow(x, kTitle);
        if (w != 0) {
            attract = grab(x, w);
            // A frame has arrived once the window is no longer its black background.
            if (!attract.empty() && cv::countNonZero(attract.reshape(1) > 30) > static_cast<int>(attract.total() / 4))
                break;
            attract.release();
        }
        std::this_thread::sleep_for(200ms);
    }
    ASSERT_NE(w, 0u) << "no window titled " << kTitle << "\n" << readFileBytes(log);
    ASSERT_FALSE(attract.empty()) << "no frame reached the window\n" << readFileBytes(log);
    EXPECT_EQ(attract.cols, 1280);
    EXPECT_EQ(attract.rows, 720);

    // Space is the Start button: the visitor's session begins and the front guide replaces the attract screen
    // (its preview of the empty booth differs from the attract screen in about a quarter of the pixels, measured
    // 25 %; the attract screen's own turning head changes far fewer).
    // (After the flow's press guard, 0.5 s from the screen appearing, in which a press is taken for the previous
    // visitor's bounce and ignored: the first frame can reach the window well within it.)
    std::this_thread::sleep_for(1s);
    sendKey(x, w, XK_space);
    bool started = false;
    cv::Mat guide;
    for (auto until = std::chrono::steady_clock::now() + 20s; std::chrono::steady_clock::now() < until;) {
        started = readFileBytes(log).find("a visitor started a session") != std::string::npos;
        if (started) {
            guide = grab(x, w);
            if (differingShare(attract, guide) > 0.15) break;
        }
        std::this_thread::sleep_for(200ms);
    }
    EXPECT_TRUE(started) << readFileBytes(log);
    ASSERT_FALSE(guide.empty());
    EXPECT_GT(differingShare(attract, guide), 0.15) << "the window still shows the attract screen";
    XCloseDisplay(x);

    EXPECT_EQ(kiosk.terminate(20s), 0) << readFileBytes(log);
    const std::string out = readFileBytes(log);
    EXPECT_NE(out.find("window 1280x720 on " + *display), std::string::npos) << out;
}
