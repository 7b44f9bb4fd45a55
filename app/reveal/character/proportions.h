// Narita's character-maker proportions (METHODS §2): the face width and height l_f0, l_f1 and the ratios r0..r7
// from the 21 feature points, the two tilts the thesis found missing, slider values in [0, 1] for a game's
// character maker, and the character.json document.
//
// Every length is the thesis' formula: |X sin θ| or |X cos θ| with θ the angle between the face line (the
// temples' segment, Pf0-Pf1) and X, i.e. X's component perpendicular to, or along, the face line. The formulas
// take absolute values, so they do not depend on the image's orientation, position or scale, nor on which way a
// vector is taken.
//
// r1 is the seed's formula (2.6)-(2.8) as written: both eye centres are projected onto the face line from the
// same temple Pf0, so r1 is where the pair of eyes sits between the temples (about 0.5 for any symmetric face);
// the seed's prose measures each eye from its own temple, which gives 1/2 - eyeSpacing/2 instead. Both are
// reported: eyeSpacing (the eye centres' distance along the face line / l_f0) is what a character maker's "eye
// distance" slider needs.
#pragma once

#include "reveal/character/narita_points.h"

#include <nlohmann/json.hpp>

#include <array>
#include <map>
#include <string>
#include <string_view>

namespace avatarbooth {

struct CharacterProportions {
    double lf0 = 0.0;  // face width |Pf1 - Pf0|, in the points' unit (pixels or millimetres)
    double lf1 = 0.0;  // face height 2 |(Pf2 - Pf0) sin θf0|
    // r0 face aspect l_f1/l_f0, r1 eye position, r2 eye size, r3 ear position, r4 ear size, r5 brow position,
    // r6 nose position, r7 mouth position (METHODS §2's table).
    std::array<double, 8> r{};
    double eyeSpacing = 0.0;   // extra: |(Pe_l - Pe_r) cos θ| / l_f0
    double eyeTiltDeg = 0.0;   // extra: inner-to-outer eye corner against the face line, + = outer corner higher
    double browTiltDeg = 0.0;  // extra: inner-to-outer brow end against the face line, + = outer end higher
};

// Throws BoothError(NoFace) when the temples coincide (l_f0 = 0).
CharacterProportions computeProportions(const NaritaPoints& points);

// One slider of the character maker: the quantity it sets, and the range mapped onto [0, 1].
struct SliderRange {
    std::string_view key;       // "face_aspect", ...
    std::string_view quantity;  // "r0", ..., "eye_spacing", "eye_tilt_deg", "brow_tilt_deg"
    double lo = 0.0, hi = 1.0;  // slider 0 and slider 1
    std::string_view meaning;
};

// The 11 sliders. Ranges: about the adult spread around the average face as this mapping measures it (the
// built-in base head measures near the middle of each; see proportions.cpp for the numbers and why).
const std::array<SliderRange, 11>& sliderRanges();

double proportionQuantity(const CharacterProportions& p, std::string_view quantity);
void setProportionQuantity(CharacterProportions& p, std::string_view quantity, double value);

// clamp((value - lo) / (hi - lo), 0, 1)
double sliderFromValue(const SliderRange& range, double value);
double valueFromSlider(const SliderRange& range, double slider);
// key -> slider value, for every slider.
std::map<std::string, double> slidersOf(const CharacterProportions& p);
// Every quantity clamped into its slider's range.
CharacterProportions clampToSliderRanges(CharacterProportions p);

// The character.json document's measured part: the method, each point (pixels) and where it came from, l_f0 and
// l_f1, r0..r7, the extras, Narita's sliders with their ranges ("narita_sliders"), and the mapping's warnings. The
// model's own sliders (MakeHuman's modifiers, "sliders") are added by character_outputs.
nlohmann::json characterJson(const NaritaMapping& mapping, const CharacterProportions& proportions);

}  // namespace avatarbooth
