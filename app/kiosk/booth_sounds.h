// What the booth sounds like: a beep on each number of the countdown, the camera's shutter as the photo is taken
// (the flash screen), a chime when the avatar is revealed. The cues come from the screens the flow shows
// (SoundCues, plain logic); BoothSounds plays them through drivers/sound's player, off the main loop.
#pragma once

#include "booth/flow_types.h"
#include "drivers/sound/sound_player.h"
#include "drivers/sound/sound_settings.h"

#include <memory>
#include <optional>
#include <string>

namespace avatarbooth {

enum class SoundCue { Tick, Shutter, Reveal };

// The cue a screen asks for when it is shown, once: each new number of a countdown, the flash, the reveal.
class SoundCues {
public:
    std::optional<SoundCue> screen(const ScreenModel& screen);

private:
    ScreenId last_ = ScreenId::Attract;
    int lastCount_ = 0;
};

class BoothSounds {
public:
    // The booth's sounds, or null (with `note` saying why) when [sound] is off, when there is no sound card and the
    // device is ALSA's default, or when the device cannot be opened or a clip of the sound theme is missing (the
    // booth goes on silently).
    static std::unique_ptr<BoothSounds> open(const SoundSettings& settings, std::string& note);

    // Plays the cue of `screen`, if it has one, as of `when` (the moment the screen changed; returns at once).
    // The countdown's beeps keep its rhythm however late the loop comes round: each number's beep is asked for
    // when that number came up (`countdownAge` before `when`), and the next number's a second after it, ahead of
    // time; a beep asked for ahead is taken back when the countdown ends early or its number comes at another time.
    void screen(const ScreenModel& screen, SoundPlayer::Time when = std::chrono::steady_clock::now());

    SoundPlayer& player() { return player_; }

private:
    BoothSounds(const SoundSettings& settings);
    SoundPlayer player_;
    SoundCues cues_;
    int tick_ = -1, shutter_ = -1, reveal_ = -1;
    struct AheadTick {
        int number;
        SoundPlayer::Time due;
        long long voice;
    };
    std::optional<AheadTick> ahead_;  // the next number's beep, asked for ahead of time
};

}  // namespace avatarbooth
