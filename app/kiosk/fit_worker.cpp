// The kiosk's fitting worker (see fit_worker.h).
#include "kiosk/fit_worker.h"

#include "reveal/character/character_outputs.h"

#include <spdlog/spdlog.h>

#include <condition_variable>
#include <deque>

namespace avatarbooth {

struct FitWorker::State {
    std::shared_ptr<std::mutex> detectorMutex;
    std::shared_ptr<const BaseHead> base;  // the pipeline refers to it: it lives as long as the State
    std::optional<CharacterSettings> character;
    KioskQueue* queue = nullptr;           // null once the worker is gone: nothing is posted then
    std::mutex mutex;
    std::condition_variable wake;
    bool loading = true;
    bool quit = false;
    std::unique_ptr<FitPipeline> pipeline;
    std::deque<Job> jobs;  // fits and front photos to analyse ahead, oldest first
    std::uint64_t running = 0;
    std::atomic<bool> cancelRunning{false};

    // Posts under the State's lock, so that the queue is never used after the worker let go of it.
    void post(KioskMessage m) {
        std::lock_guard lock(mutex);
        if (queue) queue->post(std::move(m));
    }
};

FitWorker::FitWorker(FitSettings settings, std::shared_ptr<const BaseHead> base, std::optional<CharacterSettings> character,
                     std::shared_ptr<std::mutex> detectorMutex, KioskQueue& queue)
    : state_(std::make_shared<State>()) {
    state_->detectorMutex = std::move(detectorMutex);
    state_->base = std::move(base);
    state_->character = std::move(character);
    state_->queue = &queue;
    loader_ = std::thread([state = state_, settings = std::move(settings)] { load(*state, settings); });
    fitter_ = std::thread([state = state_] { work(*state); });
}

FitWorker::~FitWorker() {
    bool loading = false;
    {
        std::lock_guard lock(state_->mutex);
        state_->quit = true;
        state_->queue = nullptr;
        state_->cancelRunning = true;
        loading = state_->loading;
    }
    state_->wake.notify_all();
    fitter_.join();  // waiting for the model or a job: wakes at once (a fit in flight stops at its next step)
    if (!loading) {
        loader_.join();
        return;
    }
    spdlog::info("stopping while the landmark model is still loading: its thread is left to the process's exit");
    loader_.detach();
}

void FitWorker::submit(std::uint64_t job, cv::Mat front, cv::Mat side) {
    {
        std::lock_guard lock(state_->mutex);
        std::erase_if(state_->jobs, [](const Job& j) { return !j.frontOnly; });
        state_->jobs.push_back(Job{job, std::move(front), std::move(side), false});
    }
    state_->wake.notify_all();
}

void FitWorker::cancel(std::uint64_t job) {
    std::lock_guard lock(state_->mutex);
    std::erase_if(state_->jobs, [&](const Job& j) { return j.id == job; });
    if (state_->running == job) state_->cancelRunning = true;
}

void FitWorker::analyseFrontAhead(cv::Mat front) {
    {
        std::lock_guard lock(state_->mutex);
        state_->jobs.push_back(Job{0, std::move(front), cv::Mat(), true});
    }
    state_->wake.notify_all();
}

void FitWorker::load(State& s, const FitSettings& settings) {
    // (Not niced: nice is weighed against every process on the machine, and a model that loads minutes late keeps
    // a visitor on the processing screen; the main loop never waits for it anyway.)
    std::unique_ptr<FitPipeline> loaded;
    std::string error;
    try {
        loaded = std::make_unique<FitPipeline>(settings, *s.base);
    } catch (const std::exception& e) {
        error = e.what();
    }
    std::lock_guard lock(s.mutex);
    s.loading = false;
    if (s.quit) return;  // abandoned (or stopped) while loading: the model is dropped here, nothing logged
    if (!loaded) {
        spdlog::error("cannot load the landmark model: {}", error);
        s.queue->post(ModelLoaded{nullptr, error});
        return;
    }
    spdlog::info("landmark model loaded in {:.2f} s", loaded->modelLoadSeconds());
    s.pipeline = std::move(loaded);
    s.queue->post(ModelLoaded{s.pipeline.get(), {}});
    s.wake.notify_all();
}

void FitWorker::work(State& s) {
    std::optional<FrontAnalysis> ahead;  // of the last front photo analysed ahead
    for (;;) {
        Job job;
        {
            std::unique_lock lock(s.mutex);
            s.wake.wait(lock, [&] { return s.quit || (s.pipeline && !s.jobs.empty()); });
            if (s.quit) return;
            job = std::move(s.jobs.front());
            s.jobs.pop_front();
            s.running = job.id;
            s.cancelRunning = false;
        }
        const FitPhotoNames names;  // "front photo", "side photo": the photos are in memory
        if (job.frontOnly) {
            ahead.reset();
            try {
                std::lock_guard detector(*s.detectorMutex);
                ahead = s.pipeline->analyseFront(job.front, cv::Mat(), names);
                spdlog::info("front photo analysed ahead in {:.0f} ms",
                             1000.0 * (ahead->stageSeconds[0].second + ahead->stageSeconds[1].second));
            } catch (const std::exception& e) {
                spdlog::info("front photo not analysed ahead ({}); the fit will say", e.what());
            }
            continue;
        }
        FitEnded ended{job.id, nullptr, std::nullopt};
        try {
            const FitControl control{[&](FitStep step) { s.post(FitStepStarted{job.id, step}); },
                                     CancelToken(s.cancelRunning)};
            auto outcome = std::make_shared<FitOutcome>();
            {
                std::lock_guard detector(*s.detectorMutex);
                *outcome = s.pipeline->fit(job.front, job.side, cv::Mat(), names, control, ahead ? &*ahead : nullptr);
            }
            std::string steps;
            for (const auto& [name, seconds] : outcome->stageSeconds)
                steps += fmt::format("{}{} {:.0f} ms", steps.empty() ? "" : ", ", name, 1000.0 * seconds);
            spdlog::info("fitted: {}", steps);
            ended.outcome = std::move(outcome);
        } catch (const FitCancelled&) {
            spdlog::info("fit {} cancelled", job.id);
            continue;
        } catch (const FitError& e) {
            ended.error = e;
        } catch (const std::exception& e) {
            ended.error = FitError(ErrorKind::Internal, FitPhoto::Both, FitFault::Other, "", e.what());
        }
        const std::shared_ptr<const FitOutcome> fitted = ended.outcome;
        s.post(std::move(ended));
        if (!fitted) continue;
        // The character next, on this (un-niced) thread: the visitor watches its place on the reveal.
        CharacterEnded character{job.id, nullptr, std::nullopt};
        if (s.character) {
            try {
                character.character =
                    std::make_shared<const CharacterOutputs>(makeCharacterOutputs(*fitted, *s.base, *s.character));
            } catch (const std::exception& e) {
                character.error = e.what();
            }
        }
        s.post(std::move(character));
    }
}

}  // namespace avatarbooth
