// Analyses preview frames for the guides on its own thread, the newest frame only (older ones are dropped: the
// hint must be about what the visitor does now), and posts each analysis to the kiosk's queue.
#pragma once

#include "booth/guidance.h"
#include "kiosk/kiosk_messages.h"

#include <opencv2/core.hpp>

#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

namespace avatarbooth {

class PreviewWorker {
public:
    PreviewWorker(GuidanceSettings settings, std::mutex& detectorMutex, KioskQueue& queue);
    ~PreviewWorker();
    PreviewWorker(const PreviewWorker&) = delete;
    PreviewWorker& operator=(const PreviewWorker&) = delete;

    // The analyser is rebuilt with it by the worker thread, between two analyses (never under a running one).
    void setDetector(const LandmarkDetector* detector);
    // Offers a frame; ignored while the previous one is still waiting or being analysed.
    void offer(Photo photo, const cv::Mat& frame, FlowTime t);
    // Drops a frame not yet analysed; true when no analysis is running (the fit may take the detector). Never
    // waits: the main loop asks again next frame rather than stand still for a slow analysis.
    bool release();

private:
    struct Pending {
        Photo photo;
        cv::Mat frame;
        FlowTime t;
    };
    void run();

    GuidanceSettings settings_;
    std::mutex& detectorMutex_;
    KioskQueue& queue_;
    std::mutex mutex_;
    std::condition_variable wake_;
    const LandmarkDetector* detector_ = nullptr;
    std::unique_ptr<PreviewAnalyser> analyser_;  // used by the worker thread only
    const LandmarkDetector* analyserDetector_ = nullptr;
    std::optional<Pending> pending_;
    bool busy_ = false;
    bool quit_ = false;
    std::thread thread_;  // last: starts once everything above exists
};

}  // namespace avatarbooth
