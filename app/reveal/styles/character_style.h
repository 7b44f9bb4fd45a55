// The character style (Narita): the base head with the visitor's proportions, in flat colours, turning with the
// photo style. Before the first visitor, the base head painted with its own proportions.
#pragma once

#include "common/recent_timings.h"
#include "render/mesh_renderer.h"
#include "reveal/styles/reveal_style.h"

#include <glm/glm.hpp>

#include <memory>
#include <optional>

namespace avatarbooth {

class HeadlessEglContext;
struct BaseHead;
struct Mesh;

class CharacterStyle final : public RevealStyle {
public:
    // `context`: as PhotoStyle's.
    CharacterStyle(const BaseHead& base, HeadlessEglContext* context = nullptr);

    AvatarStyle kind() const override { return AvatarStyle::Character; }
    // The visitor's character is made by the fitting worker right after the fit: it is awaited from now on.
    StyleWork visitor(std::uint64_t visitor, const FitOutcome& fit) override;
    void character(const CharacterOutputs* character) override;
    bool pending() const override { return awaited_; }
    bool comesSoon() const override { return true; }
    const cv::Mat& frame(const AnimationFrame& pose, bool reveal, int size) override;
    std::uint64_t version() const override { return version_; }
    void addFigures(StyleFigures& figures) const override;

private:
    void show(const Mesh& mesh, const cv::Mat& texture);

    std::unique_ptr<MeshRenderer> renderer_;  // one upload per visitor
    bool loaded_ = false;
    bool awaited_ = false;
    glm::dvec3 centre_{0.0};
    double extent_ = 1.0;
    cv::Mat image_;
    std::optional<glm::dmat4> pose_;  // what image_ shows
    std::uint64_t version_ = 0;
    int renders_ = 0;
    RecentTimings renderMs_;
};

}  // namespace avatarbooth
