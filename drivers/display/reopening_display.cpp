// ReopeningDisplay: catches "the screen is gone", drops frames and reopens at a fixed interval.
#include "drivers/display/reopening_display.h"

#include "common/error.h"

#include <spdlog/spdlog.h>

namespace avatarbooth {
namespace {

std::string sizeText(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

double seconds(std::chrono::nanoseconds d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

ReopeningDisplay::ReopeningDisplay(Opener open, std::string label, FirstOpen first, cv::Size waitingSize,
                                   Rotation rotation, std::chrono::nanoseconds interval, std::shared_ptr<Clock> clock)
    : open_(std::move(open)), label_(std::move(label)), rotation_(rotation), interval_(interval),
      clock_(std::move(clock)), size_(waitingSize), lastDescription_(label_) {
    if (!clock_) clock_ = std::make_shared<SteadyClock>();
    try {
        display_ = open_();
    } catch (const BoothError& e) {
        if (e.kind() != ErrorKind::Device || first == FirstOpen::MustSucceed) throw;
        lose(e.what());
        return;
    }
    opened();
}

void ReopeningDisplay::opened() {
    everOpened_ = true;
    size_ = display_->size();
    lastDescription_ = display_->describe();
}

void ReopeningDisplay::lose(const std::string& why) {
    // Closed first: KmsDisplay's destructor gives the CRTC back and closes the DRM node, so that the device can be
    // reopened (or its driver unloaded) while the booth waits.
    display_.reset();
    const auto now = clock_->now();
    std::lock_guard lock(statusMutex_);
    if (status_.ok) {
        lostAt_ = now;
        droppedBeforeLoss_ = status_.framesDropped;
        status_.failedReopens = 0;
        if (everOpened_)
            spdlog::warn("screen lost: {}: {}; the booth goes on without it and tries to reopen it every {:.0f} s",
                         lastDescription_, why, seconds(interval_));
        else
            spdlog::warn("no screen yet: {}; the booth starts without it and tries to open it every {:.0f} s", why,
                         seconds(interval_));
    } else {
        ++status_.failedReopens;
        spdlog::debug("screen still away ({}); next try in {:.1f} s", why, seconds(interval_));
    }
    status_.ok = false;
    status_.message = "screen " + (everOpened_ ? lastDescription_ + " lost, retrying"
                                               : label_ + " not connected yet, waiting for it") +
                      " every " + std::to_string(std::chrono::duration_cast<std::chrono::seconds>(interval_).count()) +
                      " s";
    status_.lastError = why;
    nextRetry_ = now + interval_;
}

bool ReopeningDisplay::tryReopen() {
    try {
        display_ = open_();
    } catch (const BoothError& e) {
        // Whatever the reason (still no screen, the device busy, gone): keep trying, and say why in the status.
        lose(e.what());
        return false;
    }
    const bool wasOpened = everOpened_;
    const cv::Size before = size_;
    opened();
    std::lock_guard lock(statusMutex_);
    status_.ok = true;
    status_.message.clear();
    const double away = seconds(clock_->now() - lostAt_);
    if (wasOpened) {
        ++status_.recoveries;
        spdlog::info("screen back after {:.1f} s: {}{} (recovery {}, {} frames not shown)", away, lastDescription_,
                     size_ != before ? " (its size changed from " + sizeText(before) + " to " + sizeText(size_) + ")" : "",
                     status_.recoveries, status_.framesDropped - droppedBeforeLoss_);
    } else {
        spdlog::info("screen connected after {:.1f} s: {}", away, lastDescription_);
    }
    return true;
}

void ReopeningDisplay::present(const cv::Mat& bgr) {
    if (!display_ && clock_->now() >= nextRetry_) tryReopen();
    if (!display_) {
        std::lock_guard lock(statusMutex_);
        ++status_.framesDropped;
        return;
    }
    try {
        display_->present(bgr);
    } catch (const BoothError& e) {
        if (e.kind() != ErrorKind::Device) throw;
        lose(e.what());
        std::lock_guard lock(statusMutex_);
        ++status_.framesDropped;
    }
}

std::vector<KeyEvent> ReopeningDisplay::pollKeys() { return display_ ? display_->pollKeys() : std::vector<KeyEvent>{}; }

bool ReopeningDisplay::closeRequested() const { return display_ && display_->closeRequested(); }

std::string ReopeningDisplay::describe() const {
    if (display_) return display_->describe();
    if (!everOpened_) return label_ + " waiting for a screen (" + status().lastError + ")";
    return lastDescription_ + " (no screen: " + status().lastError + ")";
}

DisplayStatus ReopeningDisplay::status() const {
    std::lock_guard lock(statusMutex_);
    return status_;
}

}  // namespace avatarbooth
