// The kiosk's turntable maker (see turntable_worker.h).
#include "kiosk/turntable_worker.h"

#include "booth/animated_webp.h"
#include "common/atomic_output.h"
#include "fit/export/glb.h"
#include "render/mesh_renderer.h"
#include "render/previews.h"

#include <chrono>

namespace avatarbooth {

namespace {
double since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

TurntableEnded makeTurntable(const std::filesystem::path& keptFolder, const TurntableSpec& spec) {
    TurntableEnded done{keptFolder, 0, 0.0, 0.0, std::nullopt};
    const auto t0 = std::chrono::steady_clock::now();
    const std::filesystem::path glb = keptFolder / "avatar.glb";
    std::vector<AvatarPart> parts = readGlbParts(glb);  // the head, then eyes, brows, lashes, ...
    AnimatedWebpEncoder encoder(spec.size, spec.size, spec.frameMs, spec.quality);
    {
        // A renderer of its own for the job (as the session writer's, with one sample, supersampled): its GL context
        // and buffers go with it. This runs beside the reveal: textures finer than twice the frame are scaled down,
        // the parts' own copies are let go once uploaded (the framing needs their meshes only), and each frame is
        // encoded as it comes.
        MeshRenderer renderer(MeshRendererOptions{.maxSamples = 1, .depth = false, .maxTextureSize = 2 * spec.size});
        renderer.upload(parts);
        for (AvatarPart& part : parts) part.texture.release();
        renderTurntable(renderer, parts, spec.size, spec.frames, Antialias::Supersample4, [&](const cv::Mat& frame) {
            const auto t = std::chrono::steady_clock::now();
            encoder.add(frame);
            done.encodeSeconds += since(t);
        });
    }
    done.renderSeconds = since(t0) - done.encodeSeconds;
    const auto t1 = std::chrono::steady_clock::now();
    const std::string webp = encoder.finish();
    writeFileAtomically(keptFolder / "turntable.webp", webp);
    done.encodeSeconds += since(t1);
    done.bytes = webp.size();
    return done;
}

TurntableWorker::TurntableWorker(KioskQueue& queue, int niceness)
    : queue_(queue), thread_(
                         [this](std::filesystem::path& folder) {
                             TurntableEnded done{folder, 0, 0.0, 0.0, std::nullopt};
                             try {
                                 done = makeTurntable(folder);
                             } catch (const std::exception& e) {
                                 done.error = e.what();
                             }
                             queue_.post(std::move(done));
                         },
                         niceness) {}

}  // namespace avatarbooth
