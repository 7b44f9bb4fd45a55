// Writes a fitted session's folder (photos, avatar.glb, previews, character outputs) on a background thread, so
// that the reveal starts as soon as the fit has a mesh and a texture instead of after the ~1 s of writing.
#pragma once

#include "common/error.h"
#include "fit/fit_pipeline.h"

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

namespace avatarbooth {

class SessionWriter {
public:
    struct Done {
        std::uint64_t job = 0;
        std::filesystem::path folder;     // complete when ok; absent otherwise (the write is atomic)
        std::optional<BoothError> error;  // why it was not written
        double seconds = 0.0;
    };

    // niceness: added to the writing thread's nice value (and to the threads it starts, e.g. llvmpipe's for the
    // previews), so that the screen's thread keeps the processor while both want it. Its renderer is made on the
    // writing thread (EGL contexts belong to a thread) at the first job.
    explicit SessionWriter(int niceness = 5);
    // Finishes the job in hand (a half-written folder would be left otherwise) and drops those still queued.
    ~SessionWriter();
    SessionWriter(const SessionWriter&) = delete;
    SessionWriter& operator=(const SessionWriter&) = delete;

    // Queues a write of `outcome` into `folder` with `pipeline` (which must outlive the write). `character`: the
    // character outputs already made for it (made by the write when null).
    void submit(std::uint64_t job, std::shared_ptr<const FitOutcome> outcome, const FitPipeline* pipeline,
                std::filesystem::path folder, std::shared_ptr<const CharacterOutputs> character = nullptr);
    // A finished write, oldest first.
    std::optional<Done> take();
    // Blocks until nothing is queued or being written.
    void waitIdle();

private:
    struct Job {
        std::uint64_t id = 0;
        std::shared_ptr<const FitOutcome> outcome;
        const FitPipeline* pipeline = nullptr;
        std::filesystem::path folder;
        std::shared_ptr<const CharacterOutputs> character;
    };
    void run();

    int niceness_;
    std::mutex mutex_;
    std::condition_variable wake_, idle_;
    std::deque<Job> queue_;
    std::deque<Done> done_;
    bool busy_ = false;
    bool quit_ = false;
    std::thread thread_;  // last: starts once everything above exists
};

}  // namespace avatarbooth
