// The photo style (see photo_style.h).
#include "reveal/styles/photo_style.h"

#include "fit/fit_pipeline.h"

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

PhotoStyle::PhotoStyle(const Mesh& base, PhotoStyleOptions options, HeadlessEglContext* context)
    : renderer_(context ? std::make_unique<MeshRenderer>(
                              *context, MeshRenderer::Options{options.samples, false, options.maxTextureSize})
                        : std::make_unique<MeshRenderer>(
                              MeshRenderer::Options{options.samples, false, options.maxTextureSize})) {
    show(base, cv::Mat(8, 8, CV_8UC3, cv::Scalar(150, 170, 210)));  // skin-coloured, untextured
}

StyleWork PhotoStyle::visitor(std::uint64_t, const FitOutcome& fit) {
    if (fit.parts.empty()) show(fit.fit.mesh, fit.texture.texture);
    else show(fit.parts);
    return {};
}

void PhotoStyle::show(const std::vector<AvatarPart>& parts) {
    renderer_->upload(parts);
    if (!parts.empty()) headFraming(parts.front().mesh, centre_, extent_);
    ++uploads_;
}

void PhotoStyle::show(const Mesh& mesh, const cv::Mat& texture) {
    renderer_->upload(mesh, texture);
    headFraming(mesh, centre_, extent_);
    ++uploads_;
}

const cv::Mat& PhotoStyle::frame(const AnimationFrame& pose, bool reveal, int size) {
    static const cv::Mat kNone;
    if (size <= 0) return kNone;
    const Key key{reveal, pose.sourceFrame, size, uploads_};
    if (key == shown_ && !image_.empty()) return image_;  // a held pose: the picture has not changed
    renderer_->renderBgra(turningHeadCamera(pose.headModel, centre_, extent_, size), image_);
    shown_ = key;
    ++version_;
    return image_;
}

}  // namespace avatarbooth
