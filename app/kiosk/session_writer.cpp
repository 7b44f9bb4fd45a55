// The kiosk's background session writer: one thread, one offscreen renderer for the previews.
#include "kiosk/session_writer.h"

#include "render/mesh_renderer.h"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include <sys/resource.h>
#include <unistd.h>

namespace avatarbooth {

SessionWriter::SessionWriter(int niceness) : niceness_(niceness), thread_([this] { run(); }) {}

SessionWriter::~SessionWriter() {
    {
        std::lock_guard lock(mutex_);
        quit_ = true;
        queue_.clear();
    }
    wake_.notify_all();
    thread_.join();
}

void SessionWriter::submit(std::uint64_t job, std::shared_ptr<const FitOutcome> outcome, const FitPipeline* pipeline,
                           std::filesystem::path folder, std::shared_ptr<const CharacterOutputs> character) {
    {
        std::lock_guard lock(mutex_);
        queue_.push_back(Job{job, std::move(outcome), pipeline, std::move(folder), std::move(character)});
    }
    wake_.notify_all();
}

std::optional<SessionWriter::Done> SessionWriter::take() {
    std::lock_guard lock(mutex_);
    if (done_.empty()) return std::nullopt;
    Done d = std::move(done_.front());
    done_.pop_front();
    return d;
}

void SessionWriter::waitIdle() {
    std::unique_lock lock(mutex_);
    idle_.wait(lock, [&] { return quit_ || (queue_.empty() && !busy_); });
}

void SessionWriter::run() {
    if (niceness_ != 0) {
        // Linux keeps a nice value per thread: this lowers the writer alone, not the screen's thread.
        errno = 0;
        const int now = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
        if (errno == 0 && setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), now + niceness_) != 0)
            spdlog::debug("session writer keeps its priority: {}", std::strerror(errno));
    }
    for (;;) {
        Job job;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return quit_ || !queue_.empty(); });
            if (quit_) return;
            job = std::move(queue_.front());
            queue_.pop_front();
            busy_ = true;
        }
        Done done;
        done.job = job.id;
        done.folder = job.folder;
        const auto t0 = std::chrono::steady_clock::now();
        try {
            // A renderer (and its GL context) for this job only: held between sessions, its buffers, texture and
            // compiled shaders kept about 40 MB through every attract screen and guide. Two samples and no depth
            // target are enough for the 512-pixel preview PNGs (the peak RSS of a session is a target: issue 3).
            MeshRenderer renderer(MeshRendererOptions{.maxSamples = 2, .depth = false});
            // No input files: the photos are in memory and are written as JPEGs (file names here would be read
            // from the working directory).
            job.pipeline->write(*job.outcome, FitInputs{}, job.folder, renderer, job.character.get());
        } catch (const BoothError& e) {
            done.error = e;
        } catch (const std::exception& e) {
            done.error = BoothError(ErrorKind::Output, job.folder.string(), e.what());
        }
        done.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::lock_guard lock(mutex_);
        done_.push_back(std::move(done));
        busy_ = false;
        idle_.notify_all();
    }
}

}  // namespace avatarbooth
