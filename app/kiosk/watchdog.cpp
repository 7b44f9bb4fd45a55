// The systemd watchdog pinger (see watchdog.h).
#include "kiosk/watchdog.h"

#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

namespace avatarbooth {

WatchdogPinger::WatchdogPinger() {
    std::uint64_t usec = 0;
    if (sd_watchdog_enabled(0, &usec) <= 0 || usec == 0) {
        spdlog::info("watchdog: none asked for (no WATCHDOG_USEC), no pings");
        return;
    }
    interval_ = std::chrono::microseconds(usec / 2);
    stalledAfter_ = std::chrono::microseconds(usec);
    alive();
    spdlog::info("watchdog: a ping every {} ms while the main loop runs",
                 std::chrono::duration_cast<std::chrono::milliseconds>(interval_).count());
    thread_ = std::thread([this] { run(); });
}

WatchdogPinger::~WatchdogPinger() {
    {
        std::lock_guard lock(mutex_);
        quit_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void WatchdogPinger::run() {
    bool withheld = false;
    std::unique_lock lock(mutex_);
    for (;;) {
        if (wake_.wait_for(lock, interval_, [&] { return quit_; })) return;
        const auto age = std::chrono::steady_clock::now() -
                         std::chrono::steady_clock::time_point(std::chrono::steady_clock::duration(lastAlive_.load()));
        if (age <= stalledAfter_) {
            sd_notify(0, "WATCHDOG=1");
            if (withheld) spdlog::warn("watchdog: the main loop runs again, pings resumed");
            withheld = false;
        } else if (!withheld) {
            spdlog::error("watchdog: the main loop has not run for {:.1f} s, pings withheld",
                          std::chrono::duration<double>(age).count());
            withheld = true;
        }
    }
}

}  // namespace avatarbooth
