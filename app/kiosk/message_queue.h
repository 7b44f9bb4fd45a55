// One queue of messages from the kiosk's worker threads to its main loop, which waits on it between frames (the
// shape of rpicam-apps' MessageQueue: post from any thread, wait on one).
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>

namespace avatarbooth {

template <typename Message>
class MessageQueue {
public:
    void post(Message message) {
        {
            std::lock_guard lock(mutex_);
            queue_.push_back(std::move(message));
        }
        wake_.notify_one();
    }
    // The oldest message, waiting for one until `deadline`; nothing when none came by then.
    template <typename Clock, typename Duration>
    std::optional<Message> waitUntil(std::chrono::time_point<Clock, Duration> deadline) {
        std::unique_lock lock(mutex_);
        if (!wake_.wait_until(lock, deadline, [&] { return !queue_.empty(); })) return std::nullopt;
        Message m = std::move(queue_.front());
        queue_.pop_front();
        return m;
    }

private:
    std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<Message> queue_;
};

}  // namespace avatarbooth
