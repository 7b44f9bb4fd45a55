// The character avatar: the base head with MakeHuman's own modifiers set so that it measures given Narita
// proportions (the thesis' character maker, with the model's own sliders), with a flat toon texture instead of the
// photos: MakeHuman's toon01 skin tinted by the visitor's colours, with painted eyes, brows, mouth and hair.
//
// How the weights are found (character_modifiers.h): the base head is measured exactly as a photo is (its
// orthographic front silhouette and projected feature vertices through mapNaritaPoints); each control (a modifier,
// or a right and left pair) is measured the same way at half weight, which gives the Jacobian of the 11 quantities;
// then a bounded least-squares step over the weights, the head made and measured again, and the step repeated on
// what is still missing, so that the finished character measures the proportions it was asked for as closely as
// MakeHuman's slider ranges allow.
#pragma once

#include "reveal/character/narita_points.h"
#include "reveal/character/proportions.h"
#include "fit/head/base_head.h"

#include <opencv2/core.hpp>

#include <optional>
#include <utility>
#include <vector>
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
    int correctionRounds = 4;   // measure-and-solve rounds of the modifier weights
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
    // The model's own sliders: every modifier the character drives, by its name in the basis, with its weight in
    // [0, 1] (MakeHuman's one-sided targets: "nose/nose-trans-up" and "nose/nose-trans-down" are two).
    std::vector<std::pair<std::string, double>> modifiers;
    std::vector<std::string> warnings;  // e.g. a base head without a modifier basis (the character is that head)
};

// Builds the character for `target` (exaggerated and clamped to the slider ranges first). A base head without a
// modifier basis (the small built-in one, an operator's own) gives the base head itself, with a warning. Throws
// BoothError(Internal) when the base head cannot be measured (no eyes or brows in its features).
CharacterHead makeCharacterHead(const BaseHead& base, const CharacterProportions& target,
                                const CharacterSettings& settings = {}, const CharacterLook& look = {});

// The flat toon texture for the base head's UV layout (depends only on the base head and the colours): `toonSkin`
// (MakeHuman's toon01 on the head's UVs, any size; empty: plain white, toon01's own diffuse colour) tinted by the
// skin colour, with the hair cap, brows, eyes, blush and mouth painted over it.
cv::Mat paintCharacterTexture(const BaseHead& base, int textureSize, const CharacterLook& look,
                              const cv::Mat& toonSkin = cv::Mat());

// MakeHuman's toon01 skin laid out on the MakeHuman base head's UVs (skins/toon01.jpg beside the base head, which
// the build writes); empty when there is none. Read once.
const cv::Mat& makeHumanToonSkin();

// Skin and hair colours from the front photo: the median colour of two cheek patches, and of the silhouette over
// the top of the head (above the brow line by 1.2-1.5 times the brow-to-nose-base height); defaults where there
// is nothing to sample. Only colours are taken, never the photo itself.
CharacterLook lookFromPhoto(const cv::Mat& frontBgr, const std::array<cv::Point2d, 68>& landmarks, const cv::Mat& mask);

}  // namespace avatarbooth
