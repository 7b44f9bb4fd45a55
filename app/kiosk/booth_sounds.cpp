// The booth's sound cues (see booth_sounds.h).
#include "kiosk/booth_sounds.h"

#include "common/error.h"

namespace avatarbooth {

std::optional<SoundCue> SoundCues::screen(const ScreenModel& screen) {
    std::optional<SoundCue> cue;
    if (screen.id == ScreenId::Countdown && (last_ != ScreenId::Countdown || screen.countdown != lastCount_) &&
        screen.countdown > 0)
        cue = SoundCue::Tick;
    else if (screen.id == ScreenId::CaptureFlash && last_ != ScreenId::CaptureFlash)
        cue = SoundCue::Shutter;
    else if (screen.id == ScreenId::Reveal && last_ != ScreenId::Reveal)
        cue = SoundCue::Reveal;
    last_ = screen.id;
    lastCount_ = screen.countdown;
    return cue;
}

BoothSounds::BoothSounds(const SoundSettings& settings) : player_(settings.device, settings.volume / 100.0) {
    // The beeps are tones made here (a short A5, the countdown's rhythm); the shutter and the chime are the
    // freedesktop theme's (README, licences).
    tick_ = player_.add(makeTone(880.0, 0.12, 0.5));
    shutter_ = player_.add(loadOggVorbis(std::filesystem::path(settings.themeDir) / "camera-shutter.oga"));
    reveal_ = player_.add(loadOggVorbis(std::filesystem::path(settings.themeDir) / "complete.oga"));
}

std::unique_ptr<BoothSounds> BoothSounds::open(const SoundSettings& settings, std::string& note) {
    if (!settings.enabled) {
        note = "off ([sound] enabled = false)";
        return nullptr;
    }
    const auto cards = soundCards();
    if (settings.device == "default" && cards.empty()) {
        note = "no sound card: silent";
        return nullptr;
    }
    try {
        std::unique_ptr<BoothSounds> sounds(new BoothSounds(settings));
        note = "on: " + settings.device + (cards.empty() ? std::string() : " (card " + cards.front() + ")") +
               ", volume " + std::to_string(settings.volume) + "%";
        return sounds;
    } catch (const BoothError& e) {
        // A sound card that cannot be opened or a sound theme that is missing: the booth goes on without sound.
        note = std::string("cannot play: ") + e.what() + ": silent";
        return nullptr;
    }
}

void BoothSounds::screen(const ScreenModel& screen, SoundPlayer::Time when) {
    const auto cue = cues_.screen(screen);
    if (ahead_ && (screen.id != ScreenId::Countdown || screen.countdown > ahead_->number + 1)) {
        player_.cancel(ahead_->voice);  // the countdown ended (or started again) before that number came
        ahead_.reset();
    }
    if (!cue) return;
    if (*cue != SoundCue::Tick) {
        player_.play(*cue == SoundCue::Shutter ? shutter_ : reveal_, when);
        return;
    }
    const SoundPlayer::Time due = when - screen.countdownAge;
    // The beep asked for ahead stands when its number came when it was expected to (within a few ms).
    const bool askedAhead = ahead_ && ahead_->number == screen.countdown &&
                            std::chrono::abs(ahead_->due - due) <= std::chrono::milliseconds(5);
    if (ahead_ && !askedAhead) player_.cancel(ahead_->voice);
    if (!askedAhead) player_.play(tick_, due);
    ahead_.reset();
    if (screen.countdown > 1) {
        const SoundPlayer::Time next = due + std::chrono::seconds(1);
        ahead_ = AheadTick{screen.countdown - 1, next, player_.play(tick_, next)};
    }
}

}  // namespace avatarbooth
