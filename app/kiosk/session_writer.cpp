// The kiosk's background session writer (see session_writer.h).
#include "kiosk/session_writer.h"

#include "booth/session_folder.h"
#include "render/mesh_renderer.h"

#include <chrono>

namespace avatarbooth {

SessionWriter::SessionWriter(int previewSize, KioskQueue& queue, int niceness)
    : previewSize_(previewSize), queue_(queue), thread_([this](session::WriteFolder& job) { write(job); }, niceness) {}

void SessionWriter::write(session::WriteFolder& job) {
    FolderEnded done{job.job, job.folder, std::nullopt, 0.0};
    const auto t0 = std::chrono::steady_clock::now();
    try {
        // A renderer (and its GL context) for this job only: held between sessions, its buffers, texture and
        // compiled shaders stayed resident through every attract screen and guide. One sample, supersampled, and no
        // depth target: this renderer lives beside the reveal's, at the kiosk's peak of memory (render/previews.h).
        MeshRenderer renderer(MeshRendererOptions{.maxSamples = 1, .depth = false});
        // No photo files: the photos are in memory and are written as JPEGs.
        writeSessionFolder(*job.outcome, {{}, job.character.get(), previewSize_, Antialias::Supersample4}, job.folder,
                           renderer);
    } catch (const BoothError& e) {
        done.error = e;
    } catch (const std::exception& e) {
        done.error = BoothError(ErrorKind::Output, job.folder.string(), e.what());
    }
    done.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    queue_.post(std::move(done));
}

}  // namespace avatarbooth
