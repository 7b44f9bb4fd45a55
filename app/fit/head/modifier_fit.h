// The fit's first step (issue 21): the modifier weights that bring the base head's feature and contour vertices
// nearest their measured positions, as a bounded, regularised linear least-squares problem (the shape fitting of
// eos, Huber et al. 2016, with MakeHuman's targets for the morphable model's basis).
//
// Model: vertex v at weights w is c + S (1 + sigma) (b_v + sum_k w_k d_kv - c), seen in the front view as (x, y) and
// in the side view as (z, y), plus a translation (t_x, t_y, t_z) of the photos' frames against the head (the frames
// are placed by the eye midpoint and the ear hole of the head before its shape is known); sigma's product with the
// weights is left out (linearised: a second-order term of a few per cent of a few millimetres). Minimised:
//   sum over targets |projected vertex - target|^2 + lambda sum_k w_k^2 + lambda_s sigma^2
//     + mu sum over mirrored pairs (w_right - w_left)^2,  0 <= w_k <= 1,
//   |sigma| <= scaleRange,
// (for an outline target, the error's parts along its normal and along the outline, each with its weight),
// so w = 0 (the average head) is what the photos must argue the head away from.
#pragma once

#include "fit/head/head_views.h"
#include "fit/head/modifier_basis.h"

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth {

struct ModifierTarget {
    std::uint32_t vertex = 0;
    View view = View::Front;
    glm::dvec2 target{0.0};  // millimetres, in the view's plane
    glm::dvec2 weight{1.0};  // of each coordinate's squared error (0: the photo does not measure it)
    // A point measured on a smooth stretch of outline (a contour ray's crossing, the profile's chin or brow) says
    // how far out the outline is, not where along it the vertex lies: with a nonzero `normal` (the outline's, in
    // the view's plane) the rows are the error along the normal (weight.x: point-to-line) and along the outline
    // (weight.y, 0 for a ray's crossing: the vertex slides freely). Pinning it along the outline at full weight
    // would hold the shape at the base head's there.
    glm::dvec2 normal{0.0};
};

struct ModifierFitOptions {
    // lambda, in square millimetres per unit weight squared: a modifier at full weight must remove this much squared
    // error to be worth it (README, "How near the fit comes", has the figures this was chosen by).
    double regularisation = 30.0;
    // Groups held more firmly: the head's and the neck's shape move the whole skull, which only the outline rays see
    // (through hair); the face's landmarks alone would bend it.
    std::map<std::string, double> groupRegularisation = {{"head", 300.0}, {"neck", 300.0}};
    int maxNewtonSteps = 100;  // of the bounded solve (it ends at the optimum, after 3-12 steps on the booth's fits)
    // Huber's threshold in millimetres (0: plain least squares) and how many times the weights are made again. A
    // detected landmark is often a millimetre off, and now and then a profile point lands on the wrong bump.
    double robustMm = 1.0;
    int robustIterations = 2;
    // Modifier groups held at 0: the ears, which no photo measurement sees (the outline rays pass above and below
    // them), would otherwise be bent to fit rays that meet hair.
    std::vector<std::string> fixedGroups = {"ears"};
    // The subject's right and left modifiers of one slider ("eyes/r-eye-push1-in" and "eyes/l-eye-push1-in", the
    // cheeks') cost mirrorRegularisation * (w_right - w_left)^2 (square millimetres) apart: faces are nearly
    // symmetric, and each eye or cheek alone follows dlib's scatter on its own side (README, "How near the fit
    // comes", has the figures; 100 and up gave the same).
    double mirrorRegularisation = 1000.0;
    // The head's size, as one more unknown: a uniform change sigma of the given scaling about its centre,
    // within +-scaleRange, costing scaleRegularisation * sigma^2 (square millimetres). The scaling the head fit starts
    // from is one width (dlib's jaw points 0 and 16, a few pixels off on a photo, and wider or narrower against the
    // eyes from one person to the next); all the targets together say the size better. 0: the size is held.
    // At 20000 a change of 5 % costs 50 mm^2, more than a modifier at full weight: on the booth's fits the size
    // moves by about 1 % (README, "How near the fit comes", has the figures).
    double scaleRange = 0.15;
    double scaleRegularisation = 20000.0;
};

struct ModifierFit {
    std::vector<double> weights;       // one per modifier, in [0, 1]
    glm::dvec3 translation{0.0};       // of the frames, millimetres
    double scaleChange = 0.0;          // sigma: the head is the given scaling times (1 + sigma) about the centre
    double rmsBeforeMm = 0.0, rmsAfterMm = 0.0;  // over the targets, at w = 0 and at the solution
};

// basePositions: the base head's (unscaled) positions; scale and centre: the per-axis scaling about the ear-hole
// centre that the measured extents gave (S and c above).
ModifierFit fitModifiers(const ModifierBasis& basis, const std::vector<glm::dvec3>& basePositions, const glm::dvec3& scale,
                         const glm::dvec3& centre, const std::vector<ModifierTarget>& targets,
                         const ModifierFitOptions& options = {});

// The basis's mirrored pairs (right, left) by name: "group/r-..." and "group/l-...".
std::vector<std::pair<std::size_t, std::size_t>> mirroredModifiers(const ModifierBasis& basis);

// The solver underneath, for any small bounded quadratic problem (the character's sliders use it too): minimises
// 1/2 x^T N x - g^T x over lo <= x <= hi (N dense, n x n row-major, symmetric positive definite; lo == hi holds a
// variable), from x, which is moved into the box first; at most maxSteps projected Newton steps.
void minimiseInBox(const std::vector<double>& N, const std::vector<double>& g, const std::vector<double>& lo,
                   const std::vector<double>& hi, std::vector<double>& x, int maxSteps = 100);

}  // namespace avatarbooth
