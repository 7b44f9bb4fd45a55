// The systemd watchdog (sd_notify WATCHDOG=1), pinged from its own thread while the kiosk's main loop is alive.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace avatarbooth {

// Pings at half of WatchdogSec (WATCHDOG_USEC, sd_watchdog_enabled(): the convention sd_notify(3) gives), so the
// pings keep their rate however long one frame takes on a slow board -- but only while the main loop is alive:
// every loop iteration calls alive(), and when none has for a whole WatchdogSec the pings stop (logged once) and
// systemd kills and restarts the hung booth. Without a watchdog in the environment (no WatchdogSec, or not under
// systemd) it sends nothing: pings nobody asked for would only fill a notify socket that is not read.
class WatchdogPinger {
public:
    WatchdogPinger();
    ~WatchdogPinger();
    WatchdogPinger(const WatchdogPinger&) = delete;
    WatchdogPinger& operator=(const WatchdogPinger&) = delete;

    void alive() { lastAlive_.store(std::chrono::steady_clock::now().time_since_epoch().count()); }

private:
    void run();

    std::chrono::steady_clock::duration interval_ = std::chrono::seconds(1);
    std::chrono::steady_clock::duration stalledAfter_ = std::chrono::seconds(10);
    std::atomic<std::chrono::steady_clock::rep> lastAlive_{0};
    std::mutex mutex_;
    std::condition_variable wake_;
    bool quit_ = false;
    std::thread thread_;  // last: starts once everything above exists
};

}  // namespace avatarbooth
