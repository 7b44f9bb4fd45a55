// Hair and beard from the two photos (issue 22): which of the bundled hair styles the visitor wears, read from
// where hair-coloured pixels lie in the two silhouettes around the face, the hair's colour, and whether a beard or
// moustache shows. Photos, silhouettes and landmarks in; a plain HairEstimate out.
#pragma once

#include <opencv2/core.hpp>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace avatarbooth {

// The hair styles the avatar can wear (one bundled MakeHuman proxy each; None: bald, no hair part).
enum class HairStyle { None, Short, Bob, Long, Ponytail };

inline constexpr std::array<HairStyle, 5> kHairStyles{HairStyle::None, HairStyle::Short, HairStyle::Bob, HairStyle::Long,
                                                     HairStyle::Ponytail};

constexpr const char* toString(HairStyle style) {
    switch (style) {
        case HairStyle::None: return "none";
        case HairStyle::Short: return "short";
        case HairStyle::Bob: return "bob";
        case HairStyle::Long: return "long";
        case HairStyle::Ponytail: return "ponytail";
    }
    return "none";
}
std::optional<HairStyle> hairStyleFromString(std::string_view name);

// What the estimate was read from: the share of hair-coloured pixels in each window (0..1), for fit.json and tests.
struct HairEvidence {
    double crown = 0.0;            // front: a band 20 mm deep under the head's top, over the face's width
    // The crown's unlike-skin pixels' median against the skin's (labDistance units). Not used: a bald scalp in the
    // top light (15-30) and blond or light brown hair on pale skin (14-26) overlap on the synthetic people.
    double hairFromSkin = 0.0;
    // Whether the crown's colour is the forehead's skin in the shade (a bald head) rather than hair: the crown's
    // unlike-skin median against the forehead's skin (5-20 mm over the brows). Shading scales the light a surface
    // sends back, so it keeps the skin's hue and (but for the room's grey light in the shade) its saturation
    // C*/(L*+16); hair has a pigment of its own.
    double foreheadFromSkin = 0.0;   // the forehead's median against the cheeks' (labDistance; over 14: a fringe)
    double crownHueShift = 0.0;      // degrees between the crown's hue and the forehead's
    double crownSaturation = 0.0;    // the crown's saturation over the forehead's
    // The share of the change from the forehead to the crown that happens within 4 mm going up (the median over the
    // crown's columns): a hairline changes the colour within a few millimetres, shading as the skull turns from the
    // light over the 50 mm and more between brows and crown.
    double hairline = 0.0;
    double besideFace = 0.0;       // front: beside the jaw, from the nose's base to the lower lip
    double belowChin = 0.0;        // front: beside the neck, 10-45 mm under the chin
    // front: the share of the clothes' pixels (70-100 mm under the chin, 40 mm either side of the middle) of the
    // hair's colour; -1 when the photo does not show them
    double clothesAsHair = -1.0;
    // side: 48-70 mm under the ear hole, from 25 mm behind to 45 mm before the head's rearmost point (its outline,
    // hair included, 25-70 mm over the ear hole)
    double behindHead = 0.0;
    double downTheBack = 0.0;      // side: 75-100 mm under the ear hole, from 30 mm behind to 40 mm before that point
    double chinDarkening = 0.0;    // skin lightness (CIE L*) of the upper cheeks minus the chin's
    double upperLipDarkening = 0.0;  // likewise, the upper lip's
    double jawDarkening = 0.0;     // likewise, the jaw's beside the mouth (the darker side... the lighter of the two)
};

struct HairEstimate {
    HairStyle style = HairStyle::None;
    cv::Vec3d colour{0.0, 0.0, 0.0};        // BGR 0..255: the median hair pixel (crown and temples), when there is hair
    bool beard = false;                     // chin and jaw darker than the cheeks
    bool moustache = false;                 // the upper lip darker than the cheeks
    cv::Vec3d beardColour{0.0, 0.0, 0.0};   // BGR, the chin's (or the upper lip's) median, when either
    cv::Vec3d skinColour{0.0, 0.0, 0.0};    // BGR, the upper cheeks' median
    cv::Vec3d hairLab{0.0, 0.0, 0.0}, skinLab{0.0, 0.0, 0.0};  // the two colour models (CIE L*a*b*, medians)
    HairEvidence evidence;
};

// The photos as the fit has them: the front with dlib's 68 points (iBUG order), the side with the profile
// landmarks (at least nasion, chin and ear_hole; fit/face/profile.h), both with their person masks (CV_8U, 255 on
// the person), pixels as taken (the side may face either way).
struct HairPhotos {
    cv::Mat front, frontMask;
    std::array<cv::Point2d, 68> frontPoints{};
    cv::Mat side, sideMask;
    std::map<std::string, cv::Point2d> sidePoints;
    bool sideNoseImageRight = true;
};

// Thresholds of the choice (hair_analysis.cpp says how they were set).
struct HairOptions {
    double bald = 0.3;           // crown share under this: no hair
    double long_ = 0.15;         // belowChin over this: the hair falls past the chin beside the neck
    // ... and besideFace over this: on its way down, long hair lies beside the face too (FRMDB's long hair 0.19-1.00
    // there); under a bald crown, whose shading reads as hair of the skin's colour, skin beside the neck reached
    // the long threshold with nothing beside the jaw (0.00-0.04: HairPopulation's people 13 and 17).
    double longBeside = 0.1;
    // With clothes of the hair's own colour under the neck (clothesAsHair over clothesAsHair: they fill the windows
    // beside the neck as hair would), long hair also needs downTheBack over longDownTheBack. HairPopulation's long
    // hair 0.69-0.86 there (FRMDB 005 0.66), its bob 29 (a brown bob over a brown shirt, which read long) 0.15, and
    // 0.19-0.20 since the base head's neck edge was smoothed (2026-12-07): the limit sits between the two, not on the
    // bob's edge.
    double clothesAsHair = 0.5;
    double longDownTheBack = 0.35;
    double beside = 0.2;         // besideFace over this (not long): a bob
    // ... but over tiedBackBeside when the side photo shows hair tied back (a ponytail's windows, below): hair tied
    // low leaves strands and the hair over the ears beside the jaw (FRMDB 004's low knot 0.43), a bob fills it
    // (FRMDB 008 0.98, HairPopulation's bob 29 0.88). One example of each: set between them.
    double tiedBackBeside = 0.65;
    // downTheBack and behindHead over this (nothing beside the face or neck): a ponytail. Measured (both windows,
    // the smaller): HairPopulation's ponytails 0.29-1.00, its short hair 0.00-0.01; FRMDB's short hair up to 0.14.
    double ponytail = 0.2;
    // The crown is the forehead's skin in the shade (no hair) when, with the forehead itself skin, its colour is
    // one shading can give (hue within shadeHueShift degrees of the forehead's, saturation over shadeSaturation of
    // it) and no hairline lies between them (HairEvidence::hairline under hairlineStep). Shading keeps the hue but
    // for the light's own tint: the bald crowns (the scan, HairPopulation's five) 3.8-5.2 degrees off the forehead,
    // FRMDB's brown hair 14-41 (redder than the skin). Shade mixes the room's grey light in: the bald crowns keep
    // 0.47-1.53 of the forehead's saturation, grey, white and black hair 0.04-0.24 (a third: between the two by
    // their ratio). Dark brown hair can have the skin's hue and saturation (HairPopulation 1, 5, 14, 16, 23): its
    // hairline tells it (0.77-1.74 of the change within 4 mm, the bald 0.17-0.23; half: most of the change at once).
    double shadeHueShift = 10.0;
    double shadeSaturation = 1.0 / 3.0;
    double hairlineStep = 0.5;
    double beardDarkening = 14.0;   // chin (and jaw at 0.5 of it) L* under the cheeks' by this much: a beard
    double moustacheDarkening = 16.0;  // the upper lip's (shaded by the nose even when bare): a moustache
};

// Throws BoothError(BadInput) when a photo or mask is empty, not BGR / CV_8U, or of another size than its photo,
// or a needed side landmark is missing.
HairEstimate estimateHair(const HairPhotos& photos, const HairOptions& options = {});

// The hair pixels of a photo (CV_8U, 255 on hair) inside its person mask, by the estimate's colour models: nearer
// the hair's colour than the skin's. All 0 when the estimate found no hair.
cv::Mat hairPixels(const cv::Mat& bgr, const cv::Mat& personMask, const HairEstimate& estimate);

// Whether a style stands out from the skull enough that the head fit should not follow its outline (a bob, long
// hair, a ponytail's knot): HeadFitOptions::hairOutlineSlackMm is set for these.
constexpr bool isBigHair(HairStyle style) {
    return style == HairStyle::Bob || style == HairStyle::Long || style == HairStyle::Ponytail;
}

// The windows estimateHair reads, drawn on a copy of each photo (hair pixels tinted), for a person to check.
std::pair<cv::Mat, cv::Mat> drawHairOverlay(const HairPhotos& photos, const HairEstimate& estimate);

}  // namespace avatarbooth
