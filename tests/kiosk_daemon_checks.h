// Checks shared by the tests that run `avatarbooth run` as a daemon (tests/e2e on the host, tests/kernel in the
// guest): the sd_notify messages it sends to our own NOTIFY_SOCKET, and which hint a guide screenshot shows.
#pragma once

#include "booth/flow_types.h"
#include "booth/screens/screens.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace avatarbooth::test {

// An abstract unix datagram socket (the name unique per process) that records every READY=1 and WATCHDOG=1 with
// the time it was read. Pass env() as NOTIFY_SOCKET to the daemon.
class NotifySocket {
public:
    explicit NotifySocket(const std::string& tag) : name_("avatarbooth-test-" + tag + "-" + std::to_string(getpid())) {
        fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::memcpy(a.sun_path + 1, name_.data(), name_.size());  // sun_path[0] = 0: abstract
        const auto len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + 1 + name_.size());
        ok_ = fd_ >= 0 && bind(fd_, reinterpret_cast<sockaddr*>(&a), len) == 0;
    }
    ~NotifySocket() {
        if (fd_ >= 0) close(fd_);
    }
    NotifySocket(const NotifySocket&) = delete;
    NotifySocket& operator=(const NotifySocket&) = delete;

    bool ok() const { return ok_; }
    std::string env() const { return "@" + name_; }

    // Reads what has arrived (call it often: the arrival time is the time of the read).
    void drain() {
        char buf[512];
        for (;;) {
            const ssize_t n = recv(fd_, buf, sizeof buf - 1, 0);
            if (n <= 0) return;
            const std::string m(buf, static_cast<std::size_t>(n));
            const auto now = std::chrono::steady_clock::now();
            if (m.find("READY=1") != std::string::npos) ready.push_back(now);
            if (m.find("WATCHDOG=1") != std::string::npos) watchdog.push_back(now);
        }
    }
    // Pings read at or after `from`, and the longest gap between two of them (or from `from` to the first).
    int pingsSince(std::chrono::steady_clock::time_point from) const {
        int n = 0;
        for (const auto& t : watchdog) n += t >= from ? 1 : 0;
        return n;
    }
    double longestGapSeconds(std::chrono::steady_clock::time_point from, std::chrono::steady_clock::time_point to) const {
        double gap = 0.0;
        auto last = from;
        for (const auto& t : watchdog) {
            if (t < from || t > to) continue;
            gap = std::max(gap, std::chrono::duration<double>(t - last).count());
            last = t;
        }
        return std::max(gap, std::chrono::duration<double>(to - last).count());
    }

    std::vector<std::chrono::steady_clock::time_point> ready, watchdog;

private:
    std::string name_;
    int fd_ = -1;
    bool ok_ = false;
};

// The hint's text pixels: near-white in the hint's box (the upper two thirds of the bottom band, as screens.cpp
// lays it out). The band darkens the preview to at most 40 %, so only text is this bright there.
inline cv::Mat hintTextMask(const cv::Mat& screen, const ScreenLayout& layout) {
    const cv::Rect box = cv::Rect(layout.bottom.x, layout.bottom.y, layout.bottom.width, layout.bottom.height * 2 / 3) &
                         cv::Rect(0, 0, screen.cols, screen.rows);
    cv::Mat mask;
    cv::inRange(screen(box), cv::Scalar(200, 200, 200), cv::Scalar(255, 255, 255), mask);
    return mask;
}

// How well a guide screenshot's hint text matches `hint` drawn by the booth's own screen renderer (same size, same
// strings): intersection over union of the text pixels, 1.0 for the same text. Different hints score well below 0.5.
inline double guideHintMatch(const cv::Mat& screenshot, ScreenId guide, Hint hint,
                             const std::filesystem::path& stringsFile = {}) {
    ScreenSettings settings;
    settings.size = screenshot.size();
    settings.stringsFile = stringsFile;
    ScreenRenderer renderer(settings);
    ScreenModel model;
    model.id = guide;
    model.photo = guide == ScreenId::SideGuide ? Photo::Side : Photo::Front;
    model.hint = hint;
    const cv::Mat expected = hintTextMask(renderer.draw(model, ScreenInputs{}), renderer.layout());
    const cv::Mat seen = hintTextMask(screenshot, renderer.layout());
    cv::Mat both, either;
    cv::bitwise_and(expected, seen, both);
    cv::bitwise_or(expected, seen, either);
    const int unionCount = cv::countNonZero(either);
    return unionCount > 0 ? static_cast<double>(cv::countNonZero(both)) / unionCount : 0.0;
}

}  // namespace avatarbooth::test
