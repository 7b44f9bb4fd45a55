// The character avatar: a stylised head made from the base head whose face parts are moved and scaled to given
// Narita proportions (the thesis' parametric deformation, as a game's character maker does with its sliders),
// with a flat, toon-like painted texture instead of the photos.
//
// How the parts move (front view, x to the subject's left, y up; depth is kept): the whole head is scaled
// vertically about the face line to the face aspect r0; then each part is a small "bone" with a smooth weight
// over the vertices around it (1 on the part, easing to 0 over a margin, front surface only): the eyes move
// along the face line (r1 and the eye spacing) and scale about their centres (r2) and turn (eye tilt); the brows
// move to their height (r5) and turn about their inner ends (brow tilt); nose (r6) and mouth (r7) move vertically;
// each ear moves to its height (r3) and stretches vertically about its top (r4). The head is measured exactly as
// a photo is (its orthographic front silhouette and projected feature vertices through mapNaritaPoints), the
// parts are corrected by what is still missing, and this is repeated a few times, so the finished character
// measures the proportions it was asked for.
#pragma once

#include "reveal/character/narita_points.h"
#include "reveal/character/proportions.h"
#include "fit/head/base_head.h"

#include <opencv2/core.hpp>

#include <optional>
#include <set>
#include <string>

namespace avatarbooth {

// Flat colours of the painted character (BGR).
struct CharacterLook {
    cv::Scalar skin{150, 188, 236};
    cv::Scalar hair{45, 55, 80};
    cv::Scalar iris{130, 90, 50};
    cv::Scalar lips{110, 110, 205};
};

struct CharacterSettings {
    int textureSize = 512;      // edge of the square painted texture, in texels (flat colours need few)
    double exaggeration = 1.0;  // 1: the given proportions; above 1 pushes each away from the base head's (caricature)
    int correctionRounds = 4;   // measure-and-correct rounds of the deformation
    double pxPerMm = 4.0;       // resolution of the silhouette the head is measured on
    // The sliders (SliderRange::key) that move the character's parts; a slider left out keeps the base head's
    // value, so an operator can keep, say, the eyes generic and play only with the face shape. Unset: all of them.
    std::optional<std::set<std::string>> sliders;
    // Skin and hair colours sampled from the photo (lookFromPhoto), or the fixed CharacterLook palette.
    bool coloursFromPhoto = true;
};

// A head mesh seen as a front photo: its orthographic front silhouette and projected feature vertices.
struct MeshFrontView {
    NaritaMappingInput input;  // landmarks (pixels), silhouette, ear hole
    double pxPerMm = 4.0;
    glm::dvec2 originMm{0.0};  // head-space (x, y) at pixel (0, 0)

    glm::dvec2 toMm(const cv::Point2d& px) const { return {originMm.x + px.x / pxPerMm, originMm.y - px.y / pxPerMm}; }
    cv::Point2d toPixel(const glm::dvec2& mm) const {
        return {(mm.x - originMm.x) * pxPerMm, (originMm.y - mm.y) * pxPerMm};
    }
};

// features: the base head whose frontFeatures index `mesh` (same topology).
MeshFrontView frontViewOf(const Mesh& mesh, const BaseHead& features, const glm::dvec3& earHole, double pxPerMm = 4.0);

struct MeasuredHead {
    NaritaMapping mapping;              // points in the view's pixels
    CharacterProportions proportions;   // lengths in pixels of that view
    MeshFrontView view;
};
MeasuredHead measureHead(const Mesh& mesh, const BaseHead& features, const glm::dvec3& earHole, double pxPerMm = 4.0);

struct CharacterHead {
    Mesh mesh;                     // base head topology and UVs, millimetres
    cv::Mat texture;               // BGR, painted
    CharacterProportions target;   // what was asked for (after exaggeration and clamping to the slider ranges)
    CharacterProportions achieved; // what the finished head measures
    CharacterProportions base;     // what the base head measures
    glm::dvec3 earHole{0.0};       // the base head's ear-hole centre after the deformation
};

// Builds the character for `target` (clamped to the slider ranges first, so a wild measurement cannot tear the
// mesh). Throws BoothError(Internal) when the base head cannot be measured (no eyes or brows in its features).
CharacterHead makeCharacterHead(const BaseHead& base, const CharacterProportions& target,
                                const CharacterSettings& settings = {}, const CharacterLook& look = {});

// The flat toon texture for the base head's UV layout (depends only on the base head and the colours).
cv::Mat paintCharacterTexture(const BaseHead& base, int textureSize, const CharacterLook& look);

// Skin and hair colours from the front photo: the median colour of two cheek patches, and of the silhouette over
// the top of the head (above the brow line by 1.2-1.5 times the brow-to-nose-base height); defaults where there
// is nothing to sample. Only colours are taken, never the photo itself.
CharacterLook lookFromPhoto(const cv::Mat& frontBgr, const std::array<cv::Point2d, 68>& landmarks, const cv::Mat& mask);

}  // namespace avatarbooth
