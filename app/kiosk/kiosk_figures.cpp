// The kiosk's figures and slow-step log (see kiosk_figures.h).
#include "kiosk/kiosk_figures.h"

#include "reveal/styles/reveal_styles.h"

#include <spdlog/spdlog.h>

#include <sys/resource.h>

namespace avatarbooth {

namespace {
using Seconds = std::chrono::duration<double>;
}  // namespace

void KioskFigures::frame(const Frame& f) {
    if (isGuide(f.screen)) {
        if (inGuide_) {  // frame intervals within one guide
            ++guideFrames_;
            guideSeconds_ += Seconds(f.presented - lastGuideFrame_).count();
        }
        lastGuideFrame_ = f.presented;
        inGuide_ = true;
    } else {
        inGuide_ = false;
    }
    if (f.screen != ScreenId::Reveal || !f.avatarShown) return;
    revealFrame_.add(Seconds(f.presented - f.drawStart).count());
    if (f.rendered) revealRender_.add(Seconds(f.renderEnd - f.drawStart).count());
    revealCompose_.add(Seconds(f.composeEnd - f.renderEnd).count());
    revealPresent_.add(Seconds(f.presented - f.composeEnd).count());
    if (sideTakenAt_) {
        captureToReveal_.add(Seconds(f.presented - *sideTakenAt_).count());
        sideTakenAt_.reset();
    }
}

// (The countdown analyses too, but the figure is about the guides, whose frames are the ones counted.)
void KioskFigures::analysed(ScreenId screen) {
    if (isGuide(screen)) ++analyses_;
}

void KioskFigures::sidePhotoTaken(Time t) { sideTakenAt_ = t; }

void KioskFigures::report(KioskReport& report, const RevealStyles& styles) const {
    report.guideFramesPerSecond = guideSeconds_ > 0.0 ? guideFrames_ / guideSeconds_ : 0.0;
    report.analysesPerSecond = guideSeconds_ > 0.0 ? analyses_ / guideSeconds_ : 0.0;
    report.sideCaptureToRevealSeconds = captureToReveal_.median();
    report.revealFrameMilliseconds = 1000.0 * revealFrame_.median();
    report.revealSlowestFrameMilliseconds = 1000.0 * revealFrame_.slowest();
    report.revealRenderMilliseconds = 1000.0 * revealRender_.median();
    report.revealComposeMilliseconds = 1000.0 * revealCompose_.median();
    report.revealPresentMilliseconds = 1000.0 * revealPresent_.median();
    report.revealRenderedShare = revealFrame_.empty() ? 0.0
        : static_cast<double>(revealRender_.count()) / static_cast<double>(revealFrame_.count());
    const StyleFigures figures = styles.figures();
    report.characterFrameMilliseconds = figures.characterMs;
    report.toonFrameMilliseconds = figures.toonMs;
    report.stageRenderMilliseconds = figures.stageMs;
    report.toonBuildSeconds = figures.toonBuildSeconds;
    report.styleFrames = figures.frames;
    report.characterRenders = figures.characterRenders;
    report.toonRenders = figures.toonRenders;
    report.stageRenders = figures.stageRenders;
    report.avatarTriangles = styles.photoTriangles();
    report.avatarSamples = styles.photoSamples();
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    report.peakRssMegabytes = static_cast<double>(usage.ru_maxrss) / 1024.0;
}

void StepTimer::mark(const char* part) {
    const auto t = std::chrono::steady_clock::now();
    parts_.emplace_back(part, Seconds(t - last_).count());
    last_ = t;
}

void StepTimer::reportIfSlow(const char* screen) const {
    const double total = Seconds(last_ - start_).count();
    if (total < kSlowStep) return;
    std::string parts;
    for (const auto& [name, seconds] : parts_)
        if (seconds >= 0.005) parts += fmt::format("{}{} {:.0f} ms", parts.empty() ? "" : ", ", name, 1000.0 * seconds);
    spdlog::warn("slow main-loop step on {}: {:.0f} ms ({})", screen, 1000.0 * total, parts);
}

}  // namespace avatarbooth
