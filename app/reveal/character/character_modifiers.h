// Narita's proportions onto MakeHuman's own modifiers (issue 22): which of the base head's modifiers move which
// ratio, how much (the Jacobian, measured on the base head exactly as a photo is measured), and the weights that
// give a head the proportions asked for.
//
// The unknowns are one-sided modifier weights in [0, 1], as in the fit (modifier_basis.h): a MakeHuman slider's two
// ends ("nose/nose-trans-down" and "nose/nose-trans-up") are two unknowns. Where a ratio is the mean of both sides
// (eye size, ear position, ...), the right and left modifiers share one weight, so the character stays symmetric;
// the eyes' sideways moves are per side, since r1 (where the pair sits between the temples) and the eye spacing
// together need both.
#pragma once

#include "reveal/character/proportions.h"
#include "fit/head/base_head.h"

#include <array>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace avatarbooth {

// One unknown: basis modifiers that take the same weight.
struct CharacterControl {
    std::vector<std::string_view> modifiers;  // names in the basis ("eyes/r-eye-size-big", ...)
    std::string_view purpose;                 // the quantity it is there for ("r2", ...), for the report
    // Times the solve's regularisation: the head's scale moves every ratio at once (they are all over the face
    // width), so it is held firmly, for the face aspect, not as a lever on the parts the other sliders cannot reach.
    double firmness = 1.0;
};

// The controls, in the order of the solve's unknowns: the two ends of each MakeHuman slider as controls 2k (the
// lower end) and 2k + 1 (the upper), never both on.
const std::vector<CharacterControl>& characterControls();

constexpr std::size_t kCharacterQuantities = 11;  // sliderRanges()'s quantities, in its order
using QuantityVector = std::array<double, kCharacterQuantities>;
QuantityVector quantitiesOf(const CharacterProportions& p);

// A base head's character model: its own proportions, the modifiers behind each control, and how each control
// moves each quantity at given weights (measured: the head with that control `probe` further, minus the head at
// the weights, over `probe`; the probe goes the other way where it would leave [0, 1]).
struct CharacterModel {
    CharacterProportions base;
    std::vector<std::vector<std::size_t>> controlModifiers;  // basis indices per control
    std::vector<QuantityVector> jacobian;                    // per control: d quantity / d weight
    std::vector<glm::dvec3> earHoleShift;                    // per control: the ear hole's move at weight 1
    std::vector<double> firmness;                            // per control (CharacterControl::firmness); empty: 1
    double pxPerMm = 4.0;
};

// The model with its Jacobian at weight 0 (the base head). Throws BoothError(Internal) when `base` has no modifier
// basis or lacks one of the controls' modifiers, or cannot be measured.
CharacterModel characterModelOf(const BaseHead& base, double pxPerMm = 4.0, double probe = 0.25);

// The head at control weights: its mesh positions (the basis applied) and its ear hole.
struct CharacterShape {
    std::vector<glm::dvec3> positions;
    glm::dvec3 earHole{0.0};
};
CharacterShape characterShape(const CharacterModel& model, const BaseHead& base, const std::vector<double>& weights);
// What that head measures, as a photo is measured.
CharacterProportions measureCharacter(const CharacterModel& model, const BaseHead& base, const std::vector<double>& weights);
// The Jacobian measured again at `weights` (whose head measures `atWeights`): the measures are not linear in the
// weights (an ear that moves changes the temples' silhouette), so each Gauss-Newton step takes it where it is.
void remeasureJacobian(CharacterModel& model, const BaseHead& base, const std::vector<double>& weights,
                       const CharacterProportions& atWeights, double probe = 0.25);

// The controls' weights for a head that should measure `target` (every quantity weighed by its slider range), from
// `current`: what the head at `weights` measures. A bounded, regularised linear least-squares (Gauss-Newton) step
// with the model's Jacobian. `regularisation` is in squared slider ranges per unit weight squared: a control at
// full weight must remove that much to be worth it.
std::vector<double> solveCharacterStep(const CharacterModel& model, const std::vector<double>& weights,
                                       const CharacterProportions& current, const CharacterProportions& target,
                                       double regularisation = 1e-4);

// MakeHuman's own two-sided sliders, as a .mhm file writes them ("modifier nose/nose-trans-down|up 0.25"): each pair
// of ends among `modifiers` (name, weight; the controls' order, the lower end first) as one value, the upper end's
// weight minus the lower's, in [-1, 1].
std::vector<std::pair<std::string, double>> makeHumanSliders(const std::vector<std::pair<std::string, double>>& modifiers);

// The basis weights (one per basis modifier) of control weights.
std::vector<double> basisWeights(const CharacterModel& model, std::size_t basisSize, const std::vector<double>& weights);

}  // namespace avatarbooth
