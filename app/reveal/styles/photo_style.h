// The photo style: the visitor's fitted, photo-textured head turning (the base head, untextured, before the first
// visitor). One mesh on the GPU, rendered offscreen at the pose it is given, again only when the pose changes.
#pragma once

#include "render/mesh_renderer.h"
#include "reveal/styles/reveal_style.h"

#include <glm/glm.hpp>

#include <cstddef>
#include <memory>

namespace avatarbooth {

class HeadlessEglContext;
struct Mesh;

struct PhotoStyleOptions {
    // 1 sample: llvmpipe's multisampling is costly (README, the reveal's figures), and at the size shown the
    // aliasing of the silhouette is slight.
    int samples = 1;
    // The texture on the screen: the avatar is shown about 450 px tall, so 1024 texels carry every detail the
    // screen can show (the exported avatar.glb keeps the full texture).
    int maxTextureSize = 1024;
};

// The camera a turning head is shown with: orthographic, `size` x `size` pixels, looking at the head's bounding-box
// centre `centre` (extent: the box's diagonal) from the front, turned the other way round that centre by the pose
// `headModel` instead of moving the mesh (one upload per visitor). Every 3-D style uses it, so the styles turn
// together.
RenderCamera turningHeadCamera(const glm::dmat4& headModel, const glm::dvec3& centre, double extent, int size);
// The centre and extent (diagonal) of a head's bounding box, for turningHeadCamera.
void headFraming(const Mesh& mesh, glm::dvec3& centre, double& extent);

// Not thread-safe: its GL context belongs to the thread that made it.
class PhotoStyle final : public RevealStyle {
public:
    // `context`: a GL context to render through (the kiosk shares one among its offscreen renders; it must
    // outlive the style); its own when null.
    PhotoStyle(const Mesh& base, PhotoStyleOptions options = {}, HeadlessEglContext* context = nullptr);

    AvatarStyle kind() const override { return AvatarStyle::Photo; }
    StyleWork visitor(std::uint64_t visitor, const FitOutcome& fit) override;
    bool pending() const override { return false; }
    const cv::Mat& frame(const AnimationFrame& pose, bool reveal, int size) override;
    std::uint64_t version() const override { return version_; }

    // Shows `mesh` from now on (the fitted visitor's head, or the base head).
    void show(const Mesh& mesh, const cv::Mat& texture);
    // Shows the avatar's parts from now on, framed by the first (the head), as the other styles frame theirs.
    void show(const std::vector<AvatarPart>& parts);
    std::size_t triangleCount() const { return renderer_->triangleCount(); }
    int samples() const { return renderer_->samples(); }

private:
    std::unique_ptr<MeshRenderer> renderer_;
    glm::dvec3 centre_{0.0};
    double extent_ = 1.0;
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
};

}  // namespace avatarbooth
