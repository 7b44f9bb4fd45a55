// The preview analysis worker (see preview_worker.h).
#include "kiosk/preview_worker.h"

#include "kiosk/thread_priority.h"

#include <spdlog/spdlog.h>

#include <chrono>

namespace avatarbooth {

PreviewWorker::PreviewWorker(GuidanceSettings settings, std::mutex& detectorMutex, KioskQueue& queue)
    : settings_(std::move(settings)), detectorMutex_(detectorMutex), queue_(queue), thread_([this] { run(); }) {}

PreviewWorker::~PreviewWorker() {
    {
        std::lock_guard lock(mutex_);
        quit_ = true;
    }
    wake_.notify_all();
    thread_.join();
}

void PreviewWorker::setDetector(const LandmarkDetector* detector) {
    std::lock_guard lock(mutex_);
    detector_ = detector;
}

void PreviewWorker::offer(Photo photo, const cv::Mat& frame, FlowTime t) {
    {
        std::lock_guard lock(mutex_);
        if (busy_ || pending_) return;
        pending_ = Pending{photo, frame.clone(), t};
    }
    wake_.notify_all();
}

bool PreviewWorker::release() {
    std::lock_guard lock(mutex_);
    pending_.reset();
    return !busy_;
}

void PreviewWorker::run() {
    lowerThisThreadsPriority(5);  // the hint may lag a frame; the screen and the watchdog must not
    for (;;) {
        Pending job;
        const LandmarkDetector* detector = nullptr;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return quit_ || pending_.has_value(); });
            if (quit_) return;
            job = std::move(*pending_);
            pending_.reset();
            busy_ = true;
            detector = detector_;
        }
        if (!analyser_ || detector != analyserDetector_) {
            analyser_ = std::make_unique<PreviewAnalyser>(detector, PreviewAnalyser::Options{});
            analyserDetector_ = detector;
        }
        std::optional<PreviewAnalysed> result;
        const auto t0 = std::chrono::steady_clock::now();
        try {
            std::lock_guard detectorLock(detectorMutex_);
            result = analyser_->analyse(job.photo, job.frame, settings_, job.t);
        } catch (const std::exception& e) {
            spdlog::warn("preview analysis failed: {}", e.what());
        }
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        // (Posted before the worker says it is free: a fit waiting for the detector then sees this result first.)
        if (result) queue_.post(PreviewEnded{*result, seconds});
        std::lock_guard lock(mutex_);
        busy_ = false;
    }
}

}  // namespace avatarbooth
