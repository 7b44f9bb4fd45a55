// The character and toon styles and the tile stage on the reveal and attract screens (see reveal_styles.h).
#include "reveal/styles/reveal_styles.h"

#include "reveal/character/character_head.h"
#include "reveal/styles/avatar_stage.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/recent_timings.h"
#include "fit/face/profile.h"
#include "fit/fit_pipeline.h"
#include "render/mesh_renderer.h"
#include "reveal/stage/stage_view.h"
#include "reveal/toon/toon_billboard.h"

#include <spdlog/spdlog.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace avatarbooth {

namespace {

using Clock = std::chrono::steady_clock;

// The toon is drawn at the scale `avatarbooth toon` uses: toonFromPhotos makes the head 320 units high, the image
// leaves room around it for the turn.
const cv::Size kToonSize(400, 440);
constexpr double kToonUnitsPerPixel = 1.0;

cv::Mat withAlpha(const cv::Mat& bgr, const cv::Mat& mask) {
    cv::Mat channels[4];
    cv::split(bgr, channels);
    channels[3] = mask;
    cv::Mat bgra;
    cv::merge(channels, 4, bgra);
    return bgra;
}

// The head's turn as a billboard yaw: where the camera (on +z) stands in the head's own frame, in degrees around
// the vertical axis (0 front, + the character's left side; see toon::ViewDirection).
double toonYaw(const AnimationFrame& frame) {
    const glm::dvec3 c = glm::inverse(frame.headWorld) * glm::dvec3(0.0, 0.0, 1.0);
    return glm::degrees(std::atan2(c.x, c.z));
}

// The built toon and its strip, ready to show and to keep.
struct ToonResult {
    std::uint64_t job = 0;
    std::shared_ptr<const toon::ToonModel> model;   // null when drawing failed
    double seconds = 0.0;
};

// Draws the toon of one visitor at a time on its own thread (region splitting and matching take a second or more).
class ToonWorker {
public:
    explicit ToonWorker(const RevealSettings& settings) : settings_(settings), thread_([this] { run(); }) {}
    ~ToonWorker() {
        {
            std::lock_guard lock(mutex_);
            quit_ = true;
        }
        wake_.notify_all();
        thread_.join();
    }
    void submit(std::uint64_t job, const StyleInputs& in) {
        {
            std::lock_guard lock(mutex_);
            job_ = Job{job, in.front, in.frontMask, in.side, in.sideMask, in.sideNoseImageRight, in.sideChinRow,
                       toon::ToonLandmarks{in.frontLandmarks, in.sideLandmarks}};
        }
        wake_.notify_all();
    }
    std::optional<ToonResult> take() {
        std::lock_guard lock(mutex_);
        auto r = std::move(result_);
        result_.reset();
        return r;
    }
    // The strip of the last job once rendered (after its model: the head shows first, the strip is for keeping).
    std::optional<std::pair<std::uint64_t, std::vector<std::pair<std::string, std::string>>>> takeStrip() {
        std::lock_guard lock(mutex_);
        auto r = std::move(strip_);
        strip_.reset();
        return r;
    }

private:
    struct Job {
        std::uint64_t id = 0;
        cv::Mat front, frontMask, side, sideMask;
        bool noseRight = true;
        int chinRow = -1;
        toon::ToonLandmarks landmarks;
    };
    void run() {
        for (;;) {
            Job job;
            {
                std::unique_lock lock(mutex_);
                wake_.wait(lock, [&] { return quit_ || job_.has_value(); });
                if (quit_) return;
                job = std::move(*job_);
                job_.reset();
            }
            ToonResult r;
            r.job = job.id;
            const auto t0 = Clock::now();
            try {
                // Both photos come from one camera at one height: the side photo's chin row cuts both masks to the
                // head (as `avatarbooth toon` does).
                cv::Mat frontMask = job.frontMask.clone(), sideMask = job.sideMask.clone();
                if (job.chinRow >= 0) {
                    frontMask.rowRange(std::clamp(job.chinRow, 0, frontMask.rows), frontMask.rows).setTo(0);
                    sideMask.rowRange(std::clamp(job.chinRow, 0, sideMask.rows), sideMask.rows).setTo(0);
                }
                r.model = std::make_shared<toon::ToonModel>(toon::toonFromPhotos(
                    job.front, frontMask, job.side, sideMask, job.noseRight, settings_.toonColours, 320, job.landmarks));
            } catch (const std::exception& e) {
                spdlog::warn("the toon could not be drawn: {}", e.what());
            }
            r.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
            if (r.model)
                spdlog::info("toon drawn in {:.2f} s ({} matched regions)", r.seconds, r.model->pairs.size());
            const std::shared_ptr<const toon::ToonModel> model = r.model;
            {
                std::lock_guard lock(mutex_);
                result_ = std::move(r);
            }
            std::vector<std::pair<std::string, std::string>> strip;
            try {
                if (model) strip = toon::turntableFrames(*model, settings_.toonStripFrames, kToonSize, kToonUnitsPerPixel);
            } catch (const std::exception& e) {
                spdlog::warn("the toon's turntable strip could not be made: {}", e.what());
            }
            std::lock_guard lock(mutex_);
            strip_ = std::make_pair(job.id, std::move(strip));
        }
    }

    RevealSettings settings_;
    std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<Job> job_;
    std::optional<ToonResult> result_;
    std::optional<std::pair<std::uint64_t, std::vector<std::pair<std::string, std::string>>>> strip_;
    bool quit_ = false;
    std::thread thread_;  // last: starts once everything above exists
};

}  // namespace

StyleInputs styleInputsFrom(const FitOutcome& o) {
    StyleInputs in;
    in.front = o.front;
    in.frontMask = o.frontMask;
    in.side = o.side;
    in.sideMask = o.sideMask;
    in.sideNoseImageRight = o.sideNoseImageRight;
    in.frontLandmarks = o.frontLandmarks.points;
    in.sideLandmarks = o.sideLandmarks;
    if (const auto it = o.sideLandmarks.find("chin"); it != o.sideLandmarks.end())
        in.sideChinRow = static_cast<int>(it->second.y) + 1;
    return in;
}

struct RevealStyles::Impl {
    RevealSettings settings;
    StageSettings stageSettings;
    std::vector<AnimationFrame> reveal, attract;
    double fps = 24.0;
    int size = 480;

    // Character: its own renderer (one upload per visitor), the last image and the pose it was drawn at.
    std::unique_ptr<MeshRenderer> characterRenderer;
    bool characterLoaded = false;
    bool characterAwaited = false;  // the visitor's character is being made (its place says so on the reveal)
    glm::dvec3 centre{0.0};
    double extent = 1.0;
    cv::Mat characterImage;
    std::optional<glm::dmat4> characterPose;

    // Toon.
    std::unique_ptr<ToonWorker> toonWorker;
    std::uint64_t toonJob = 0;
    bool toonDrawing = false;  // the model is being made (its place shows "drawing you")
    bool toonPending = false;  // the model or its strip is being made
    std::shared_ptr<const toon::ToonModel> toonModel;
    std::vector<std::pair<std::string, std::string>> toonStrip;
    cv::Mat toonImage;
    double toonImageYaw = 1000.0;

    std::optional<stage::TileMap> stageMap;  // read at start-up; the view is made for the first band it fills
    std::unique_ptr<stage::StageView> stage;
    HeadlessEglContext* context = nullptr;  // shared with the kiosk's other offscreen renders (null: their own)

    RecentTimings characterMs, toonMs, stageMs;  // the recent frames are the ones that matter
    StyleFigures figures;
    std::uint64_t version = 1;
    std::vector<std::pair<std::string, bool>> lastListed;  // the styles the last fill() listed, with an image or not

    void showCharacter(const Mesh& mesh, const cv::Mat& texture) {
        characterRenderer->upload(mesh, texture);
        headFraming(mesh, centre, extent);
        characterLoaded = true;
        characterAwaited = false;
        characterPose.reset();
        ++version;
    }

    // The same view of the head as the kiosk's photo avatar (AvatarStage), so the two turn together.
    cv::Mat renderCharacter(const glm::dmat4& model) {
        if (characterPose && *characterPose == model) return characterImage;  // a held frame
        const auto t0 = Clock::now();
        characterRenderer->renderBgra(turningHeadCamera(model, centre, extent, size), characterImage);
        characterPose = model;
        characterMs.add(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        ++figures.characterRenders;
        ++version;
        return characterImage;
    }

    cv::Mat renderToonAt(double yaw) {
        yaw = std::round(yaw * 2.0) / 2.0;  // half a degree: invisible, and a slow turn reuses images
        if (!toonImage.empty() && yaw == toonImageYaw) return toonImage;
        const auto t0 = Clock::now();
        cv::Mat coverage;
        const cv::Mat bgr = toon::renderToon(*toonModel, yaw, kToonSize, kToonUnitsPerPixel, 2, &coverage);
        toonImage = withAlpha(bgr, coverage);
        toonImageYaw = yaw;
        toonMs.add(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
        ++figures.toonRenders;
        ++version;
        return toonImage;
    }

    void collectToon() {
        if (!toonWorker) return;
        if (auto r = toonWorker->take(); r && r->job == toonJob) {  // else nothing new, or an earlier visitor's
            toonDrawing = false;
            toonModel = r->model;
            toonImage.release();
            figures.toonBuildSeconds = r->seconds;
        }
        if (auto strip = toonWorker->takeStrip(); strip && strip->first == toonJob) {
            toonPending = false;
            toonStrip = std::move(strip->second);
        }
    }
};

RevealStyles::RevealStyles(const RevealSettings& reveal, const StageSettings& stageSettings,
                           const AnimationSettings& animation, const BaseHead& base, int avatarSize,
                           HeadlessEglContext* context)
    : impl_(std::make_unique<Impl>()) {
    Impl& s = *impl_;
    s.context = context;
    s.settings = reveal;
    s.stageSettings = stageSettings;
    s.reveal = playAnimation(revealMotion(), animation);
    s.attract = playAnimation(attractMotion(), animation);
    s.fps = animation.fps;
    s.size = avatarSize;
    if (reveal.shows(AvatarStyle::Character)) {
        // Like the photo avatar (AvatarStage): 1 sample, no depth, a texture no larger than the screen shows.
        const MeshRenderer::Options options{1, false, 512};
        s.characterRenderer = context ? std::make_unique<MeshRenderer>(*context, options)
                                      : std::make_unique<MeshRenderer>(options);
        // Before any visitor: the base head painted as a character, with its own (average) proportions.
        s.showCharacter(base.mesh, paintCharacterTexture(base, 256, CharacterLook{}));
    }
    if (reveal.shows(AvatarStyle::Toon)) s.toonWorker = std::make_unique<ToonWorker>(reveal);
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

void RevealStyles::visitor(StyleInputs inputs) {
    Impl& s = *impl_;
    if (s.characterRenderer) {
        s.characterLoaded = false;
        s.characterAwaited = true;
    }
    if (s.toonWorker) {
        s.toonModel.reset();  // never the previous visitor's toon on this one's reveal
        s.toonStrip.clear();
        s.toonImage.release();
        s.toonWorker->submit(++s.toonJob, inputs);
        s.toonPending = s.toonDrawing = true;
    }
}

void RevealStyles::visitorCharacter(const Mesh& mesh, const cv::Mat& texture) {
    if (impl_->characterRenderer && !mesh.positions.empty()) impl_->showCharacter(mesh, texture);
}

void RevealStyles::visitorWithoutCharacter() {
    Impl& s = *impl_;
    if (!s.characterAwaited) return;
    s.characterAwaited = false;
    s.characterLoaded = false;
    ++s.version;
}

std::uint64_t RevealStyles::version() const { return impl_->version; }

void RevealStyles::fill(ScreenInputs& in, bool reveal, std::chrono::milliseconds since, const ScreenLayout& layout) {
    Impl& s = *impl_;
    s.collectToon();
    const auto& clip = reveal ? s.reveal : s.attract;
    const AnimationFrame* frame = nullptr;
    if (!clip.empty()) {
        const auto index = static_cast<std::size_t>(std::chrono::duration<double>(since).count() * s.fps) % clip.size();
        frame = &clip[index];
    }
    in.avatars.clear();
    complete_ = true;
    for (const AvatarStyle style : s.settings.styles) {
        switch (style) {
            case AvatarStyle::Photo:
                in.avatars.push_back({toString(style), in.avatar});
                if (in.avatar.empty()) complete_ = false;
                break;
            case AvatarStyle::Character:
                if (s.characterLoaded && frame) {
                    in.avatars.push_back({toString(style), s.renderCharacter(frame->headModel)});
                } else if (reveal && s.characterAwaited) {
                    in.avatars.push_back({toString(style), cv::Mat()});  // its place, with "making" in it
                    complete_ = false;
                }
                break;
            case AvatarStyle::Toon:
                if (s.toonModel && frame) {
                    in.avatars.push_back({toString(style), s.renderToonAt(toonYaw(*frame))});
                } else if (reveal && s.toonDrawing) {
                    in.avatars.push_back({toString(style), cv::Mat()});  // its place, with "drawing you" in it
                    complete_ = false;
                }
                break;
        }
    }
    if (s.stageMap && !s.stage && !layout.stage.empty()) {
        // Enough copies of the map side by side to fill the band (a square map under a wide screen).
        const int copies = stage::copiesToFill(*s.stageMap, static_cast<double>(layout.stage.width) / layout.stage.height);
        s.stage = std::make_unique<stage::StageView>(stage::buildStage(stage::repeatAcross(*s.stageMap, copies)),
                                                      100.0, s.context);
    }
    if (s.stage && !layout.stage.empty()) {
        const int before = s.stage->renders();
        const double elevation =
            stage::sweepElevation(std::chrono::duration<double>(since).count(), s.stageSettings.sweepSeconds,
                                  s.stageSettings.lowAngleDeg);
        // At half the band's resolution, scaled up by the screen: flat-coloured boxes lose little, and llvmpipe
        // (fill-rate bound) draws a quarter of the pixels on the frames the camera moves.
        in.stage = s.stage->render(elevation, cv::Size(std::max(1, layout.stage.width / 2), std::max(1, layout.stage.height / 2)));
        if (s.stage->renders() != before) {
            s.stageMs.add(s.stage->lastRenderMilliseconds());
            ++s.figures.stageRenders;
            ++s.version;
        }
    }
    std::vector<std::pair<std::string, bool>> listed;
    for (const StyledAvatar& a : in.avatars) listed.emplace_back(a.style, !a.image.empty());
    if (listed != s.lastListed) {
        s.lastListed = std::move(listed);
        ++s.version;
    }
    ++s.figures.frames;
}

bool RevealStyles::characterPending() const { return impl_->characterAwaited; }

bool RevealStyles::showsToon() const { return impl_->toonWorker != nullptr; }

bool RevealStyles::toonSettled() const {
    impl_->collectToon();
    return !impl_->toonPending;
}

bool RevealStyles::writeToonStrip(const std::filesystem::path& sessionFolder) {
    Impl& s = *impl_;
    s.collectToon();
    if (s.toonStrip.empty()) return false;
    StagedDirectory dir(sessionFolder / "toon", "turntable_000.png");
    for (const auto& [name, png] : s.toonStrip) writeFileAtomically(dir.staging() / name, png);
    dir.commit();
    return true;
}

StyleFigures RevealStyles::figures() const {
    StyleFigures f = impl_->figures;
    f.characterMs = impl_->characterMs.median();
    f.toonMs = impl_->toonMs.median();
    f.stageMs = impl_->stageMs.median();
    return f;
}

}  // namespace avatarbooth
