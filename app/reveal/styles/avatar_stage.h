// The avatar turning on the kiosk's reveal and attract screens: one head mesh on the GPU, rendered offscreen with
// the head pose of the keyframed motion, and re-rendered only when that pose changes.
#pragma once

#include "reveal/animation/avatar_motion.h"
#include "booth/flow_types.h"
#include "fit/head/mesh.h"
#include "render/mesh_renderer.h"

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace avatarbooth {

struct AvatarStageOptions {
    // 1 sample: llvmpipe's multisampling is costly (the reveal's avatar render measured 56 ms at 2 samples against
    // 21 ms at 1, idle, 1280x720), and at the size shown the aliasing of the silhouette is slight.
    int samples = 1;
    // The texture on the screen: the avatar is shown about 450 px tall, so 1024 texels carry every detail the
    // screen can show (the exported avatar.glb keeps the full texture).
    int maxTextureSize = 1024;
};

// The camera the kiosk shows a turning head with: orthographic, `size` x `size` pixels, looking at the head's
// bounding-box centre `centre` (extent: the box's diagonal) from the front, turned the other way round that centre
// by the pose `headModel` instead of moving the mesh (one upload per visitor). The character style uses the same
// camera, so the styles turn together.
RenderCamera turningHeadCamera(const glm::dmat4& headModel, const glm::dvec3& centre, double extent, int size);
// The centre and extent (diagonal) of a head's bounding box, for turningHeadCamera.
void headFraming(const Mesh& mesh, glm::dvec3& centre, double& extent);

// Not thread-safe: its GL context belongs to the thread that made it.
class AvatarStage {
public:
    // `context`: a GL context to render through (the kiosk shares one among its offscreen renders; it must outlive
    // the stage); its own when null.
    explicit AvatarStage(const AnimationSettings& animation, AvatarStageOptions options = {},
                         HeadlessEglContext* context = nullptr);

    // Uploads the head to show from now on (the fitted visitor, or the base head before any visitor).
    void show(const Mesh& mesh, const cv::Mat& texture);
    bool loaded() const { return loaded_; }

    // The head (BGRA, coverage as alpha, `size` x `size` pixels: render at the size shown, no rescaling) at `since`
    // into the reveal's or the attract's motion. The limited animation holds a pose for several screen frames:
    // then the last image is returned again without rendering (version() unchanged). Empty before show().
    const cv::Mat& frame(bool reveal, Millis since, int size);
    // Changes whenever frame() returns a new picture (never 0 once one was rendered).
    std::uint64_t version() const { return version_; }
    // The time of the last render (render + read-back), and how many were made.
    double lastRenderSeconds() const { return lastRenderSeconds_; }
    std::uint64_t renders() const { return version_; }
    std::size_t triangleCount() const { return renderer_->triangleCount(); }
    int samples() const { return renderer_->samples(); }

private:
    std::unique_ptr<MeshRenderer> renderer_;
    std::vector<AnimationFrame> reveal_, attract_;
    double fps_;
    glm::dvec3 centre_{0.0};
    double extent_ = 1.0;
    bool loaded_ = false;
    cv::Mat image_;
    // What image_ shows: which motion, which source frame of it, at which size, of which upload.
    struct Key {
        bool reveal = false;
        int sourceFrame = -1;
        int size = 0;
        std::uint64_t upload = 0;
        bool operator==(const Key&) const = default;
    };
    Key shown_;
    std::uint64_t uploads_ = 0;
    std::uint64_t version_ = 0;
    double lastRenderSeconds_ = 0.0;
};

}  // namespace avatarbooth
