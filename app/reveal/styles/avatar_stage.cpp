// The kiosk's avatar stage: pose from the motion clip, a render only when the pose changes.
#include "reveal/styles/avatar_stage.h"

#include <chrono>

namespace avatarbooth {

RenderCamera turningHeadCamera(const glm::dmat4& headModel, const glm::dvec3& centre, double extent, int size) {
    const glm::dmat4 inverse = glm::inverse(headModel);
    const glm::dvec3 eye = glm::dvec3(inverse * glm::dvec4(centre + glm::dvec3(0.0, 0.0, 3.0 * extent), 1.0));
    const glm::dvec3 target = glm::dvec3(inverse * glm::dvec4(centre, 1.0));
    const glm::dvec3 up = glm::normalize(glm::dvec3(inverse * glm::dvec4(0.0, 1.0, 0.0, 0.0)));
    RenderCamera camera = RenderCamera::orthographic(eye, target, up, extent * 0.85 / size, size, size);
    camera.background = cv::Scalar(0, 0, 0);  // transparent black: BGRA's alpha is the coverage
    return camera;
}

void headFraming(const Mesh& mesh, glm::dvec3& centre, double& extent) {
    glm::dvec3 lo, hi;
    mesh.bounds(lo, hi);
    centre = (lo + hi) * 0.5;
    extent = glm::length(hi - lo);
}

AvatarStage::AvatarStage(const AnimationSettings& animation, AvatarStageOptions options, HeadlessEglContext* context)
    : renderer_(context ? std::make_unique<MeshRenderer>(
                              *context, MeshRenderer::Options{options.samples, false, options.maxTextureSize})
                        : std::make_unique<MeshRenderer>(
                              MeshRenderer::Options{options.samples, false, options.maxTextureSize})),
      reveal_(playAnimation(revealMotion(), animation)),
      attract_(playAnimation(attractMotion(), animation)),
      fps_(animation.fps) {}

void AvatarStage::show(const Mesh& mesh, const cv::Mat& texture) {
    renderer_->upload(mesh, texture);
    headFraming(mesh, centre_, extent_);
    loaded_ = true;
    ++uploads_;
}

const cv::Mat& AvatarStage::frame(bool reveal, Millis since, int size) {
    static const cv::Mat kNone;
    const auto& clip = reveal ? reveal_ : attract_;
    if (!loaded_ || clip.empty() || size <= 0) return kNone;
    const auto index =
        static_cast<std::size_t>(std::chrono::duration<double>(since).count() * fps_) % clip.size();
    const AnimationFrame& pose = clip[index];
    const Key key{reveal, pose.sourceFrame, size, uploads_};
    if (key == shown_ && !image_.empty()) return image_;  // a held pose: the picture has not changed

    const auto t0 = std::chrono::steady_clock::now();
    renderer_->renderBgra(turningHeadCamera(pose.headModel, centre_, extent_, size), image_);
    shown_ = key;
    ++version_;
    lastRenderSeconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return image_;
}

}  // namespace avatarbooth
