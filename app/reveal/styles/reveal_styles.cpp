// The styles side by side, their shared motion and the tile stage (see reveal_styles.h).
#include "reveal/styles/reveal_styles.h"

#include "common/error.h"
#include "common/recent_timings.h"
#include "fit/fit_pipeline.h"
#include "reveal/stage/stage_view.h"
#include "reveal/styles/character_style.h"
#include "reveal/styles/toon_style.h"

namespace avatarbooth {

std::vector<std::unique_ptr<RevealStyle>> makeRevealStyles(const RevealSettings& reveal, const BaseHead& base,
                                                           HeadlessEglContext* context, PhotoStyleOptions photo) {
    std::vector<std::unique_ptr<RevealStyle>> styles;
    for (const AvatarStyle style : reveal.styles) {
        switch (style) {
            case AvatarStyle::Photo: styles.push_back(std::make_unique<PhotoStyle>(base.mesh, photo, context)); break;
            case AvatarStyle::Character: styles.push_back(std::make_unique<CharacterStyle>(base, context)); break;
            case AvatarStyle::Toon: styles.push_back(std::make_unique<ToonStyle>(reveal)); break;
        }
    }
    return styles;
}

struct RevealStyles::Impl {
    std::vector<std::unique_ptr<RevealStyle>> styles;
    PhotoStyle* photo = nullptr;  // among them, when listed
    std::vector<AnimationFrame> reveal, attract;
    double fps = 24.0;
    std::uint64_t visitor = 0;

    StageSettings stageSettings;
    std::optional<stage::TileMap> stageMap;  // read at start-up; the view is made for the first band it fills
    std::unique_ptr<stage::StageView> stage;
    HeadlessEglContext* context = nullptr;
    RecentTimings stageMs;
    int stageRenders = 0, frames = 0;

    std::uint64_t version = 1;  // bumped by the list of places or the stage; the styles' own versions add to it
    std::vector<std::pair<std::string, bool>> lastListed;  // the places the last fill() listed, with a picture or not

    std::uint64_t stylesVersion() const {
        std::uint64_t v = version;
        for (const auto& s : styles) v += s->version();
        return v;
    }

    void fillStage(StyleImages& out, std::chrono::milliseconds since, cv::Size band) {
        out.stage.release();
        if (!stageMap || band.width <= 0 || band.height <= 0) return;
        if (!stage) {
            // Enough copies of the map side by side to fill the band (a square map under a wide screen).
            const int copies = stage::copiesToFill(*stageMap, static_cast<double>(band.width) / band.height);
            stage = std::make_unique<stage::StageView>(stage::buildStage(stage::repeatAcross(*stageMap, copies)), 100.0,
                                                       context);
        }
        const int before = stage->renders();
        const double elevation = stage::sweepElevation(std::chrono::duration<double>(since).count(),
                                                       stageSettings.sweepSeconds, stageSettings.lowAngleDeg);
        // At half the band's resolution, scaled up by the screen: flat-coloured boxes lose little, and llvmpipe
        // (fill-rate bound) draws a quarter of the pixels on the frames the camera moves.
        out.stage = stage->render(elevation, cv::Size(std::max(1, band.width / 2), std::max(1, band.height / 2)));
        if (stage->renders() != before) {
            stageMs.add(stage->lastRenderMilliseconds());
            ++stageRenders;
            ++version;
        }
    }
};

RevealStyles::RevealStyles(const RevealSettings& reveal, const StageSettings& stageSettings,
                           const AnimationSettings& animation, const BaseHead& base, HeadlessEglContext* context,
                           PhotoStyleOptions photo)
    : impl_(std::make_unique<Impl>()) {
    Impl& s = *impl_;
    s.context = context;
    s.styles = makeRevealStyles(reveal, base, context, photo);
    for (const auto& style : s.styles)
        if (style->kind() == AvatarStyle::Photo) s.photo = static_cast<PhotoStyle*>(style.get());
    s.reveal = playAnimation(revealMotion(), animation);
    s.attract = playAnimation(attractMotion(), animation);
    s.fps = animation.fps;
    s.stageSettings = stageSettings;
    if (stageSettings.enabled) {
        const std::filesystem::path map = stageSettings.map.empty() ? stage::defaultStageMapFile() : stageSettings.map;
        stage::TileMap tiles;
        try {
            tiles = stage::loadTileMap(map);
        } catch (const BoothError& e) {
            // The operator's map: a mistake in it is a configuration error (where = file:line:column).
            throw BoothError(ErrorKind::BadConfig, e.where(), std::string("stage map: ") + e.what());
        }
        (void)stage::buildStage(tiles);  // any rule's complaint now, not on the first frame
        s.stageMap = std::move(tiles);
    }
}

RevealStyles::~RevealStyles() = default;

std::vector<StyleWork> RevealStyles::visitor(const FitOutcome& fit) {
    Impl& s = *impl_;
    ++s.visitor;
    std::vector<StyleWork> work;
    for (const auto& style : s.styles)
        if (StyleWork w = style->visitor(s.visitor, fit)) work.push_back(std::move(w));
    return work;
}

void RevealStyles::visitorCharacter(const CharacterOutputs* character) {
    for (const auto& style : impl_->styles) style->character(character);
}

std::uint64_t RevealStyles::version() const { return impl_->stylesVersion(); }

void RevealStyles::fill(StyleImages& out, bool reveal, std::chrono::milliseconds since, const std::vector<int>& sizes,
                        cv::Size stageBand) {
    Impl& s = *impl_;
    out.avatars.clear();
    complete_ = true;
    photoShown_ = false;
    const auto& clip = reveal ? s.reveal : s.attract;
    if (!clip.empty()) {
        const auto index = static_cast<std::size_t>(std::chrono::duration<double>(since).count() * s.fps) % clip.size();
        const AnimationFrame& pose = clip[index];
        for (std::size_t i = 0; i < s.styles.size(); ++i) {
            RevealStyle& style = *s.styles[i];
            const int size = sizes.empty() ? 400 : sizes[std::min(i, sizes.size() - 1)];
            const cv::Mat& image = style.frame(pose, reveal, size);
            if (!image.empty()) {
                out.avatars.push_back({toString(style.kind()), image});
                if (&style == s.photo) photoShown_ = true;
            } else if (style.pending()) {
                complete_ = false;
                if (reveal) out.avatars.push_back({toString(style.kind()), cv::Mat()});  // its place, "making"
            }
        }
    }
    s.fillStage(out, since, stageBand);
    std::vector<std::pair<std::string, bool>> listed;
    for (const StyledAvatar& a : out.avatars) listed.emplace_back(a.style, !a.image.empty());
    if (listed != s.lastListed) {
        s.lastListed = std::move(listed);
        ++s.version;
    }
    ++s.frames;
}

bool RevealStyles::awaitingSoon() const {
    for (const auto& style : impl_->styles)
        if (style->pending() && style->comesSoon()) return true;
    return false;
}

bool RevealStyles::settled() const {
    for (const auto& style : impl_->styles)
        if (!style->settled()) return false;
    return true;
}

bool RevealStyles::hasExtras() const {
    for (const auto& style : impl_->styles)
        if (style->hasExtras()) return true;
    return false;
}

bool RevealStyles::writeInto(const std::filesystem::path& keptSession) {
    bool wrote = false;
    for (const auto& style : impl_->styles) wrote = style->writeInto(keptSession) || wrote;
    return wrote;
}

std::size_t RevealStyles::photoTriangles() const { return impl_->photo ? impl_->photo->triangleCount() : 0; }
int RevealStyles::photoSamples() const { return impl_->photo ? impl_->photo->samples() : 0; }

StyleFigures RevealStyles::figures() const {
    StyleFigures f;
    for (const auto& style : impl_->styles) style->addFigures(f);
    f.stageMs = impl_->stageMs.median();
    f.stageRenders = impl_->stageRenders;
    f.frames = impl_->frames;
    return f;
}

}  // namespace avatarbooth
