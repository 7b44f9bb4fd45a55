// [sound]: the booth's sounds (countdown beeps, the shutter, the reveal).
#pragma once

#include <string>

namespace avatarbooth {

struct SoundSettings {
    // On when the booth has a sound card (or `device` names another output); false turns every sound off.
    bool enabled = true;
    // Loudness of every sound, 0-100 (percent of the clips' own level; the card's mixer is left alone).
    int volume = 80;
    // The ALSA PCM ("default": the first sound card, through ALSA's plug and dmix; "hw:1" another card;
    // "file:FILE=/tmp/booth.wav,FORMAT=wav" records instead of playing, for tests).
    std::string device = "default";
    // Where the freedesktop sound theme's clips are (Debian sound-theme-freedesktop).
    std::string themeDir = "/usr/share/sounds/freedesktop/stereo";
};

}  // namespace avatarbooth
