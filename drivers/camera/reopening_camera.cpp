// ReopeningCamera: catches "camera gone", reopens with doubling delays, renumbers frames across reopens.
#include "drivers/camera/reopening_camera.h"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace avatarbooth {

ReopeningCamera::ReopeningCamera(Opener open, std::string label, ReopenPolicy policy,
                                 std::shared_ptr<Clock> clock)
    : open_(std::move(open)), label_(std::move(label)), policy_(policy), clock_(std::move(clock)),
      delay_(policy.firstDelay) {
    if (!clock_) clock_ = std::make_shared<SteadyClock>();
    try {
        camera_ = open_();
        everOpened_ = true;
        lastDescription_ = camera_->describe();
    } catch (const BoothError& e) {
        if (e.kind() != ErrorKind::Device) throw;
        lose(e.what());
    }
}

void ReopeningCamera::lose(const std::string& why) {
    camera_.reset();
    const auto now = clock_->now();
    {
        std::lock_guard lock(statusMutex_);
        if (status_.ok) {
            delay_ = policy_.firstDelay;
            status_.failedReopens = 0;
            spdlog::warn("camera {} lost ({}); reopening in {} ms", label_, why,
                         std::chrono::duration_cast<std::chrono::milliseconds>(delay_).count());
        } else {
            ++status_.failedReopens;
            delay_ = std::min(delay_ * 2, policy_.maxDelay);
            spdlog::debug("camera {} still away ({}); next try in {} ms", label_, why,
                          std::chrono::duration_cast<std::chrono::milliseconds>(delay_).count());
        }
        status_.ok = false;
        status_.message = "camera " + label_ + (everOpened_ ? " disconnected, retrying" : " not found, retrying");
        status_.lastError = why;
    }
    nextRetry_ = now + delay_;
}

bool ReopeningCamera::tryReopen() {
    try {
        camera_ = open_();
        if (wantStreaming_) camera_->start();
    } catch (const std::exception& e) {
        // Whatever the reason, the kiosk keeps trying and says why; only the first open may fail for good.
        lose(e.what());
        return false;
    }
    everOpened_ = true;
    lastDescription_ = camera_->describe();
    sequenceBase_ = nextSequence_;
    std::lock_guard lock(statusMutex_);
    status_.ok = true;
    status_.message.clear();
    ++status_.recoveries;
    spdlog::info("camera {} is back: {}", label_, lastDescription_.summary());
    return true;
}

void ReopeningCamera::start() {
    wantStreaming_ = true;
    if (!camera_) return;
    try {
        camera_->start();
    } catch (const CameraGoneError& e) {
        lose(e.what());
    }
}

std::optional<CameraFrame> ReopeningCamera::nextFrame(std::chrono::milliseconds timeout) {
    wantStreaming_ = true;
    const auto deadline = clock_->now() + timeout;
    for (;;) {
        const auto now = clock_->now();
        if (!camera_) {
            if (now < nextRetry_) {
                if (nextRetry_ > deadline) {
                    clock_->sleepUntil(deadline);
                    return std::nullopt;
                }
                clock_->sleepUntil(nextRetry_);
            }
            if (!tryReopen() && clock_->now() >= deadline) return std::nullopt;
            continue;
        }
        try {
            const auto left = std::max(std::chrono::nanoseconds{0}, deadline - now);
            auto frame = camera_->nextFrame(std::chrono::ceil<std::chrono::milliseconds>(left));
            if (frame) {
                frame->sequence += sequenceBase_;
                nextSequence_ = frame->sequence + 1;
            }
            return frame;
        } catch (const CameraGoneError& e) {
            lose(e.what());
            if (clock_->now() >= deadline) return std::nullopt;
        }
    }
}

CameraFrame ReopeningCamera::captureStill() {
    if (!camera_ && !tryReopen()) throw CameraGoneError(label_, status().lastError);
    try {
        return camera_->captureStill();
    } catch (const CameraGoneError& e) {
        lose(e.what());
        throw;
    }
}

void ReopeningCamera::stop() {
    wantStreaming_ = false;
    if (camera_) camera_->stop();
}

CameraDescription ReopeningCamera::describe() const {
    if (camera_) return camera_->describe();
    auto d = lastDescription_;
    if (d.device.empty()) d.device = label_;
    d.note = status().message;
    return d;
}

CameraStatus ReopeningCamera::status() const {
    std::lock_guard lock(statusMutex_);
    return status_;
}

}  // namespace avatarbooth
