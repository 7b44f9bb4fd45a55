// The kiosk's fitting worker: loads the landmark model on one thread, then fits one job at a time on another and
// makes its character, posting each step, result and character to the kiosk's queue.
#pragma once

#include "fit/fit_pipeline.h"
#include "kiosk/kiosk_messages.h"
#include "reveal/character/character_head.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

namespace avatarbooth {

class FitWorker {
public:
    // `character`: the settings to make each fit's character with; none: no character. `detectorMutex`: held while
    // the landmark detector is in use (the preview analysis shares it).
    FitWorker(FitSettings settings, std::shared_ptr<const BaseHead> base, std::optional<CharacterSettings> character,
              std::shared_ptr<std::mutex> detectorMutex, KioskQueue& queue);
    // Cancels the fit in flight at its next step. A model still loading is left to finish on its own thread (dlib
    // reads the model file with blocking reads that cannot be interrupted, and stopping must not wait for a slow
    // card or a pipe): that thread owns everything it touches (the State) and posts nothing once told to quit.
    ~FitWorker();
    FitWorker(const FitWorker&) = delete;
    FitWorker& operator=(const FitWorker&) = delete;

    // Fits the two photos as `job` (a fit queued and not yet started is superseded).
    void submit(std::uint64_t job, cv::Mat front, cv::Mat side);
    // Cancels `job` (at its next step; it then posts nothing).
    void cancel(std::uint64_t job);
    // Analyses the front photo now (landmarks, silhouette: about a third of the fit), while the visitor turns for
    // the side photo; the fit of this very photo then starts from it. Nothing is posted.
    void analyseFrontAhead(cv::Mat front);

private:
    struct Job {
        std::uint64_t id = 0;
        cv::Mat front, side;
        bool frontOnly = false;
    };
    struct State;
    static void load(State& s, const FitSettings& settings);
    static void work(State& s);

    std::shared_ptr<State> state_;
    std::thread loader_, fitter_;
};

}  // namespace avatarbooth
