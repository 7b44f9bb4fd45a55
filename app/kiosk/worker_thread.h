// One thread that works through jobs in the order they come: the shape the session writer and the styles' worker
// share (each posts its results to the kiosk's queue itself).
#pragma once

#include "kiosk/thread_priority.h"

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace avatarbooth {

template <typename Job>
class WorkerThread {
public:
    // `work` runs on the thread, one job at a time; `niceness` lowers the thread's priority (and that of the
    // threads it starts, e.g. llvmpipe's), so that the screen's thread keeps the processor while both want it.
    WorkerThread(std::function<void(Job&)> work, int niceness) : work_(std::move(work)), niceness_(niceness) {
        thread_ = std::thread([this] { run(); });
    }
    // Finishes the job in hand (a half-done job could leave a half-written folder) and drops those still queued.
    ~WorkerThread() {
        {
            std::lock_guard lock(mutex_);
            quit_ = true;
            queued_.clear();
        }
        wake_.notify_all();
        thread_.join();
    }
    WorkerThread(const WorkerThread&) = delete;
    WorkerThread& operator=(const WorkerThread&) = delete;

    void submit(Job job) {
        {
            std::lock_guard lock(mutex_);
            queued_.push_back(std::move(job));
        }
        wake_.notify_all();
    }
    // Drops the jobs not started yet and queues these instead.
    void replaceQueued(std::vector<Job> jobs) {
        {
            std::lock_guard lock(mutex_);
            queued_.assign(std::make_move_iterator(jobs.begin()), std::make_move_iterator(jobs.end()));
        }
        wake_.notify_all();
    }
    // Blocks until nothing is queued or being worked on.
    void waitIdle() {
        std::unique_lock lock(mutex_);
        idle_.wait(lock, [&] { return quit_ || (queued_.empty() && !busy_); });
    }

private:
    void run() {
        lowerThisThreadsPriority(niceness_);
        for (;;) {
            Job job;
            {
                std::unique_lock lock(mutex_);
                wake_.wait(lock, [&] { return quit_ || !queued_.empty(); });
                if (quit_) return;
                job = std::move(queued_.front());
                queued_.pop_front();
                busy_ = true;
            }
            work_(job);
            std::lock_guard lock(mutex_);
            busy_ = false;
            idle_.notify_all();
        }
    }

    std::function<void(Job&)> work_;
    int niceness_;
    std::mutex mutex_;
    std::condition_variable wake_, idle_;
    std::deque<Job> queued_;
    bool busy_ = false;
    bool quit_ = false;
    std::thread thread_;  // started last, in the constructor's body: everything above exists by then
};

}  // namespace avatarbooth
