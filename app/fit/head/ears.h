// The base head's ears: the template by which the side photo's ear is found (fit/face/ear_locator.h), and the ears
// moved to where it is.
#pragma once

#include "fit/face/ear_locator.h"
#include "fit/head/base_head.h"
#include "fit/head/mesh.h"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth {

// The ear whose vertices are `earVertices` (the subject's right ear, x < 0), seen from its side orthographically
// with the face towards image-right, at mmPerPixel; `noseTipToTop`: the head's V (the nose tip's height under the
// top of the head, millimetres), by which the locator scales it to a photo, and `noseTip`, from which it says where
// the ear lies.
EarTemplate makeEarTemplate(const Mesh& head, const std::vector<std::uint32_t>& earVertices, double noseTipToTop,
                            const glm::dvec3& noseTip, double mmPerPixel = 0.5);

// The vertices a modifier moves rigidly (by over 0.99 of its longest offset): the ear itself for MakeHuman's ear translations
// (kRightEarTranslation: the right ear). Empty when the basis has no such modifier.
std::vector<std::uint32_t> rigidlyMovedVertices(const ModifierBasis& basis, const std::string& modifier);
// The right ear's translation, whose rigidly moved vertices are the ear the template shows and the placement moves.
inline constexpr const char* kRightEarTranslation = "ears/r-ear-trans-depth-backward";

// The template of the base head's right ear (empty without a modifier basis, which says where the ear is).
EarTemplate makeEarTemplate(const BaseHead& base);

// The ears moved so that their middle (the right ear's vertices' mean, seen from the side) lies at `photoEar`
// (side view: z, y in millimetres of the scaled head): the weights of MakeHuman's ear translations
// (ears/{r,l}-ear-trans-depth-{forward,backward}, ears/{r,l}-ear-trans-vert-{up,down}; both ears alike), within
// their sliders' ranges. `head`: the fitted head, on which the modifiers' offsets count times axisScale.
struct EarPlacement {
    bool placed = false;            // the basis has the ears' translations
    std::vector<double> weights;    // to add to the modifier weights (basis order)
    glm::dvec2 offsetMm{0.0};       // photoEar less the head's ear middle (forward, up)
    glm::dvec2 shiftMm{0.0};        // what the weights move the ears by (the offset within the ranges)
    std::vector<std::uint32_t> earVertices;  // the right ear's (rigidlyMovedVertices of kRightEarTranslation)
};
EarPlacement placeEars(const ModifierBasis& basis, const Mesh& head, const glm::dvec3& axisScale,
                       const glm::dvec2& photoEar);

// What the placement moves each vertex by (head millimetres: the modifiers' offsets times axisScale). The ear itself
// moves fully; round it the move fades out (smoothly, by the share of its longest offset each vertex has in the
// modifier, from 0.99 down to kEarMoveFadesTo) sooner than MakeHuman's own falloff, which drags the cheek and the
// temple along up to 70 mm ahead of the ear hole (a third of the ear's move on the face's side).
std::vector<std::pair<std::uint32_t, glm::dvec3>> earDisplacements(const ModifierBasis& basis, const EarPlacement& placement,
                                                                   const glm::dvec3& axisScale);
// Where the move has faded out (the trials that chose it: README, "ears").
inline constexpr double kEarMoveFadesTo = 0.35;

}  // namespace avatarbooth
