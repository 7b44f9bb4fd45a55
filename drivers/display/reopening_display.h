// A screen that survives being switched off or unplugged: when the display reports its screen gone (a Device
// error), it is closed, reopened at a fixed interval, and drawing resumes; meanwhile frames are dropped and the
// kiosk goes on (camera, buttons, fit, sessions). The display's counterpart of ReopeningCamera.
#pragma once

#include "common/clock.h"
#include "drivers/display/display.h"

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

namespace avatarbooth {

// A fixed interval, not the camera's doubling back-off: a reopen that fails costs a few ioctls (the connector
// still reports no screen), and a visitor switching the monitor back on expects it back within a moment.
// 2 s is what systemd's RestartSec gave before the kiosk reopened the screen itself.
inline constexpr std::chrono::seconds kDisplayReopenInterval{2};

struct DisplayStatus {
    bool ok = true;
    // Empty when ok, else for the log and the operator: "screen kms /dev/dri/card1 HDMI-A-1 lost, retrying every
    // 2 s" (or "... not connected yet, waiting for it" when it has never opened).
    std::string message;
    std::string lastError;          // the error that made it go away, or the last failed reopen
    int failedReopens = 0;          // attempts since it went away
    int recoveries = 0;             // times it came back (the first open after waiting counts as none)
    std::uint64_t framesDropped = 0;  // frames presented while there was no screen
};

class ReopeningDisplay final : public Display {
public:
    // Opens the display (e.g. a KmsDisplay of the settings); throws its BoothError.
    using Opener = std::function<std::unique_ptr<Display>()>;

    // Whether a Device error at the first open throws (the display is expected now: `auto` passes over it) or
    // starts the display lost and waits for the screen (`auto` on a board whose monitor is off, `kms`).
    enum class FirstOpen { MustSucceed, MayWait };

    // Opens at once. `label` names the screen in messages before it ever opened ("kms /dev/dri/card1"). Until the
    // first open succeeds, size() is `waitingSize` (the configured panel turned by `rotation`). Errors other than
    // Device (bad configuration) always throw.
    ReopeningDisplay(Opener open, std::string label, FirstOpen first, cv::Size waitingSize, Rotation rotation,
                     std::chrono::nanoseconds interval = kDisplayReopenInterval, std::shared_ptr<Clock> clock = nullptr);

    // Presents on the open display. While lost: tries to reopen when the interval has passed since the last try
    // (never more often), and otherwise drops the frame and returns at once (the kiosk paces its own loop). A
    // Device error from the display loses it (logged once); other errors are thrown.
    void present(const cv::Mat& bgr) override;
    // The open display's size, or the last one known while lost (the kiosk keeps composing at it); it changes when
    // the screen comes back with another mode.
    cv::Size size() const override { return size_; }
    Rotation rotation() const override { return rotation_; }
    std::vector<KeyEvent> pollKeys() override;
    bool closeRequested() const override;
    // The display's description, or the last one known with "(no screen: why)" while lost, or "LABEL waiting for a
    // screen (why)" before it ever opened.
    std::string describe() const override;

    // Thread-safe.
    DisplayStatus status() const;
    // The display now open, or nullptr while lost (tests read the KMS display's writeback through it).
    Display* current() { return display_.get(); }

private:
    bool tryReopen();
    void lose(const std::string& why);
    void opened();

    Opener open_;
    std::string label_;
    Rotation rotation_;
    std::chrono::nanoseconds interval_;
    std::shared_ptr<Clock> clock_;
    std::unique_ptr<Display> display_;
    cv::Size size_;
    bool everOpened_ = false;
    std::string lastDescription_;
    SteadyTime lostAt_{}, nextRetry_{};
    std::uint64_t droppedBeforeLoss_ = 0;  // status_.framesDropped when it went away
    mutable std::mutex statusMutex_;
    DisplayStatus status_;
};

}  // namespace avatarbooth
