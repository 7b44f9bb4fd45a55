// Settings of the avatar styles on the reveal and attract screens ([reveal]) and of the tile stage under them ([stage]).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace avatarbooth {

// The ways the visitor's head is shown: the photo-fitted head (NTT), the character made from the base head with the
// visitor's proportions (Narita), and the two-view billboard toon drawn from the photos (Kitamura).
enum class AvatarStyle { Photo, Character, Toon };

inline const char* toString(AvatarStyle s) {
    switch (s) {
        case AvatarStyle::Photo: return "photo";
        case AvatarStyle::Character: return "character";
        case AvatarStyle::Toon: return "toon";
    }
    return "photo";
}
inline std::optional<AvatarStyle> parseAvatarStyle(std::string_view word) {
    if (word == "photo") return AvatarStyle::Photo;
    if (word == "character") return AvatarStyle::Character;
    if (word == "toon") return AvatarStyle::Toon;
    return std::nullopt;
}

// [reveal]: which styles are shown, side by side, in this order of importance: the first is drawn largest in the
// middle, the next to its left, the next to its right. (Side by side rather than switched with a button: the
// visitor's two buttons already mean keep and retake, and seeing all of them at once is the fun of it.)
struct RevealSettings {
    std::vector<AvatarStyle> styles{AvatarStyle::Photo, AvatarStyle::Character, AvatarStyle::Toon};
    int toonColours = 6;       // flat colours of the toon drawing
    int toonStripFrames = 24;  // PNG frames of the toon's turntable strip kept in the session (toon/turntable_NNN.png)

    bool shows(AvatarStyle s) const {
        for (AvatarStyle x : styles)
            if (x == s) return true;
        return false;
    }
};

// [stage]: Kitamura's tile stage under the avatars on the attract and reveal screens.
struct StageSettings {
    bool enabled = true;
    std::filesystem::path map;  // the tile map; empty: the one the booth ships (stage.map next to strings.toml)
    double sweepSeconds = 16.0;  // one camera sweep: top-down look (45 degrees) -> low view -> back, with holds
    double lowAngleDeg = 12.0;   // the camera's elevation at the ordinary 3-D end of the sweep
};

}  // namespace avatarbooth
