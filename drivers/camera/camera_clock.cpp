// The real and the manual camera clock.
#include "drivers/camera/camera_clock.h"

#include <thread>

namespace avatarbooth {

std::chrono::nanoseconds SteadyCameraClock::now() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch());
}

void SteadyCameraClock::sleepUntil(std::chrono::nanoseconds t) {
    std::this_thread::sleep_until(std::chrono::steady_clock::time_point(
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(t)));
}

std::chrono::nanoseconds ManualCameraClock::now() {
    std::lock_guard lock(mutex_);
    return now_;
}

void ManualCameraClock::sleepUntil(std::chrono::nanoseconds t) {
    std::lock_guard lock(mutex_);
    if (t > now_) now_ = t;
}

void ManualCameraClock::advance(std::chrono::nanoseconds by) {
    std::lock_guard lock(mutex_);
    now_ += by;
}

}  // namespace avatarbooth
