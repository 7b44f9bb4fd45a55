// The character style (see character_style.h).
#include "reveal/styles/character_style.h"

#include "reveal/character/character_outputs.h"
#include "reveal/styles/photo_style.h"

#include <chrono>

namespace avatarbooth {

CharacterStyle::CharacterStyle(const BaseHead& base, HeadlessEglContext* context) {
    // Like the photo style: 1 sample, no depth, a texture no larger than the screen shows.
    const MeshRenderer::Options options{1, false, 512};
    renderer_ = context ? std::make_unique<MeshRenderer>(*context, options) : std::make_unique<MeshRenderer>(options);
    show(base.mesh, paintCharacterTexture(base, 256, CharacterLook{}));
}

StyleWork CharacterStyle::visitor(std::uint64_t, const FitOutcome&) {
    loaded_ = false;
    awaited_ = true;
    ++version_;
    return {};
}

void CharacterStyle::character(const CharacterOutputs* character) {
    if (character && !character->head.mesh.positions.empty()) {
        show(character->head.mesh, character->head.texture);
        return;
    }
    if (!awaited_) return;
    awaited_ = false;  // none comes: its place is left out
    ++version_;
}

void CharacterStyle::show(const Mesh& mesh, const cv::Mat& texture) {
    renderer_->upload(mesh, texture);
    headFraming(mesh, centre_, extent_);
    loaded_ = true;
    awaited_ = false;
    pose_.reset();
    ++version_;
}

const cv::Mat& CharacterStyle::frame(const AnimationFrame& pose, bool, int size) {
    static const cv::Mat kNone;
    if (!loaded_) return kNone;
    if (pose_ && *pose_ == pose.headModel && image_.cols == size) return image_;  // a held frame
    const auto t0 = std::chrono::steady_clock::now();
    renderer_->renderBgra(turningHeadCamera(pose.headModel, centre_, extent_, size), image_);
    pose_ = pose.headModel;
    renderMs_.add(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    ++renders_;
    ++version_;
    return image_;
}

void CharacterStyle::addFigures(StyleFigures& figures) const {
    figures.characterMs = renderMs_.median();
    figures.characterRenders = renders_;
}

}  // namespace avatarbooth
