// The character's controls (MakeHuman modifiers per Narita quantity), their measured Jacobian and the bounded solve.
#include "reveal/character/character_modifiers.h"

#include "fit/head/modifier_fit.h"

#include "reveal/character/character_head.h"
#include "common/error.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace avatarbooth {
namespace {

// Which modifiers move which quantity; each MakeHuman slider's two ends follow each other, lower end first. Face aspect: the head's vertical and horizontal scale and the chin's height
// (l_f1 is twice the chin's distance from the eye line, l_f0 the head's width there). Eye position and spacing:
// each eye's sideways move. Eye size, ear position and size, brow, nose and mouth height: the part's own size or
// vertical move. Eye tilt: the outer eye corner up or down (MakeHuman's eye-corner1); brow tilt: the brows' angle.
const std::vector<CharacterControl> kControls = {
    {{"head/head-scale-vert-less"}, "r0", 100.0},
    {{"head/head-scale-vert-more"}, "r0", 100.0},
    {{"head/head-scale-horiz-less"}, "r0", 100.0},
    {{"head/head-scale-horiz-more"}, "r0", 100.0},
    {{"chin/chin-height-min"}, "r0"},
    {{"chin/chin-height-max"}, "r0"},
    {{"eyes/r-eye-move-in"}, "r1, eye_spacing"},
    {{"eyes/r-eye-move-out"}, "r1, eye_spacing"},
    {{"eyes/l-eye-move-in"}, "r1, eye_spacing"},
    {{"eyes/l-eye-move-out"}, "r1, eye_spacing"},
    {{"eyes/r-eye-size-small", "eyes/l-eye-size-small"}, "r2"},
    {{"eyes/r-eye-size-big", "eyes/l-eye-size-big"}, "r2"},
    {{"ears/r-ear-trans-vert-down", "ears/l-ear-trans-vert-down"}, "r3"},
    {{"ears/r-ear-trans-vert-up", "ears/l-ear-trans-vert-up"}, "r3"},
    {{"ears/r-ear-height-min", "ears/l-ear-height-min"}, "r4"},
    {{"ears/r-ear-height-max", "ears/l-ear-height-max"}, "r4"},
    {{"eyebrows/eyebrows-trans-vert-less"}, "r5"},
    {{"eyebrows/eyebrows-trans-vert-more"}, "r5"},
    {{"nose/nose-trans-vert-down"}, "r6"},
    {{"nose/nose-trans-vert-up"}, "r6"},
    {{"mouth/mouth-trans-down"}, "r7"},
    {{"mouth/mouth-trans-up"}, "r7"},
    {{"eyes/r-eye-corner1-down", "eyes/l-eye-corner1-down"}, "eye_tilt_deg"},
    {{"eyes/r-eye-corner1-up", "eyes/l-eye-corner1-up"}, "eye_tilt_deg"},
    {{"eyebrows/eyebrows-angle-up"}, "brow_tilt_deg"},
    {{"eyebrows/eyebrows-angle-down"}, "brow_tilt_deg"},
};

}  // namespace

const std::vector<CharacterControl>& characterControls() { return kControls; }

QuantityVector quantitiesOf(const CharacterProportions& p) {
    QuantityVector q{};
    for (std::size_t i = 0; i < kCharacterQuantities; ++i) q[i] = proportionQuantity(p, sliderRanges()[i].quantity);
    return q;
}

std::vector<std::pair<std::string, double>> makeHumanSliders(const std::vector<std::pair<std::string, double>>& m) {
    std::vector<std::pair<std::string, double>> out;
    std::vector<bool> used(m.size(), false);
    for (std::size_t i = 0; i < m.size(); ++i)
        for (std::size_t j = i + 1; j < m.size() && !used[i]; ++j) {
            // Two ends of one slider share everything up to the last '-': "nose/nose-trans-" + "down" / "up".
            const std::size_t cut = m[i].first.rfind('-');
            if (used[j] || cut == std::string::npos || m[j].first.compare(0, cut + 1, m[i].first, 0, cut + 1) != 0 ||
                m[j].first.find('-', cut + 1) != std::string::npos)
                continue;
            out.emplace_back(m[i].first + "|" + m[j].first.substr(cut + 1), m[j].second - m[i].second);
            used[i] = used[j] = true;
        }
    return out;
}

std::vector<double> basisWeights(const CharacterModel& model, std::size_t basisSize, const std::vector<double>& weights) {
    std::vector<double> out(basisSize, 0.0);
    for (std::size_t c = 0; c < model.controlModifiers.size(); ++c)
        for (const std::size_t k : model.controlModifiers[c]) out[k] += weights[c];
    return out;
}

namespace {

// Which vertices an ear modifier moves: the ear hole moves with their mean.
std::set<std::uint32_t> earVertices(const ModifierBasis& basis) {
    std::set<std::uint32_t> out;
    for (const Modifier& m : basis.modifiers)
        if (m.group == "ears") out.insert(m.vertices.begin(), m.vertices.end());
    return out;
}

}  // namespace

CharacterShape characterShape(const CharacterModel& model, const BaseHead& base, const std::vector<double>& weights) {
    const ModifierBasis& basis = *base.modifiers;
    CharacterShape out;
    out.positions = basis.apply(base.mesh.positions, basisWeights(model, basis.modifiers.size(), weights));
    out.earHole = base.earHoleCentre;
    for (std::size_t c = 0; c < weights.size(); ++c) out.earHole += weights[c] * model.earHoleShift[c];
    return out;
}

CharacterProportions measureCharacter(const CharacterModel& model, const BaseHead& base, const std::vector<double>& weights) {
    CharacterShape shape = characterShape(model, base, weights);
    Mesh mesh;
    mesh.positions = std::move(shape.positions);
    mesh.triangles = base.mesh.triangles;
    return measureHead(mesh, base, shape.earHole, model.pxPerMm).proportions;
}

void remeasureJacobian(CharacterModel& model, const BaseHead& base, const std::vector<double>& weights,
                       const CharacterProportions& atWeights, double probe) {
    const QuantityVector q0 = quantitiesOf(atWeights);
    model.jacobian.assign(model.controlModifiers.size(), QuantityVector{});
    for (std::size_t c = 0; c < model.controlModifiers.size(); ++c) {
        std::vector<double> w = weights;
        const double step = w[c] + probe <= 1.0 ? probe : -probe;
        w[c] += step;
        const QuantityVector q = quantitiesOf(measureCharacter(model, base, w));
        for (std::size_t i = 0; i < kCharacterQuantities; ++i) model.jacobian[c][i] = (q[i] - q0[i]) / step;
    }
}

CharacterModel characterModelOf(const BaseHead& base, double pxPerMm, double probe) {
    if (!base.modifiers)
        throw BoothError(ErrorKind::Internal, "base head", "has no modifier basis: the character is made with MakeHuman's modifiers");
    const ModifierBasis& basis = *base.modifiers;
    if (basis.vertexCount != base.mesh.vertexCount())
        throw BoothError(ErrorKind::Internal, "base head", "its modifier basis belongs to another mesh");
    CharacterModel model;
    model.pxPerMm = pxPerMm;
    for (const CharacterControl& control : kControls) {
        std::vector<std::size_t> ks;
        for (const std::string_view name : control.modifiers) {
            const std::size_t k = basis.find(std::string(name));
            if (k == basis.modifiers.size())
                throw BoothError(ErrorKind::Internal, "base head", "its modifier basis lacks '" + std::string(name) + "'");
            ks.push_back(k);
        }
        model.controlModifiers.push_back(std::move(ks));
        model.firmness.push_back(control.firmness);
    }
    // The ear hole moves as the ears do: the mean displacement of every vertex an ear modifier moves.
    const std::set<std::uint32_t> ears = earVertices(basis);
    for (std::size_t c = 0; c < kControls.size(); ++c) {
        glm::dvec3 sum(0.0);
        for (const std::size_t k : model.controlModifiers[c]) {
            const Modifier& m = basis.modifiers[k];
            for (std::size_t i = 0; i < m.vertices.size(); ++i)
                if (ears.count(m.vertices[i])) sum += glm::dvec3(m.offsets[i]);
        }
        model.earHoleShift.push_back(ears.empty() ? glm::dvec3(0.0) : sum / static_cast<double>(ears.size()));
    }
    try {
        model.base = measureHead(base.mesh, base, base.earHoleCentre, pxPerMm).proportions;
        remeasureJacobian(model, base, std::vector<double>(kControls.size(), 0.0), model.base, probe);
    } catch (const BoothError& e) {
        throw BoothError(ErrorKind::Internal, "base head", std::string("cannot be measured for the character: ") + e.what());
    }
    return model;
}

std::vector<double> solveCharacterStep(const CharacterModel& model, const std::vector<double>& weights,
                                       const CharacterProportions& current, const CharacterProportions& target,
                                       double regularisation) {
    const std::size_t n = model.jacobian.size();
    const QuantityVector now = quantitiesOf(current), want = quantitiesOf(target);
    // Rows: quantity i, scaled by its slider range; right-hand side: the residual plus what the current weights give.
    std::vector<double> N(n * n, 0.0), g(n, 0.0);
    for (std::size_t i = 0; i < kCharacterQuantities; ++i) {
        const double scale = 1.0 / (sliderRanges()[i].hi - sliderRanges()[i].lo);
        double rhs = want[i] - now[i];
        for (std::size_t c = 0; c < n; ++c) rhs += model.jacobian[c][i] * weights[c];
        for (std::size_t a = 0; a < n; ++a) {
            const double ja = model.jacobian[a][i] * scale;
            g[a] += ja * rhs * scale;
            for (std::size_t b = 0; b < n; ++b) N[a * n + b] += ja * model.jacobian[b][i] * scale;
        }
    }
    for (std::size_t a = 0; a < n; ++a)
        N[a * n + a] += regularisation * (a < model.firmness.size() ? model.firmness[a] : 1.0);
    // Bounded to [0, 1] (fit/head/modifier_fit.h's solver). A slider's two ends (controls 2k and 2k + 1) are never
    // both on, as on MakeHuman's own slider: where the solution has both, the weaker end is held at 0 and the rest
    // solved again.
    std::vector<double> w = weights, lower(n, 0.0), upper(n, 1.0);
    for (std::size_t c = 0; c + 1 < n; c += 2)
        if (w[c] > 0.0 && w[c + 1] > 0.0) upper[w[c] < w[c + 1] ? c : c + 1] = 0.0;
    for (int pass = 0; pass <= static_cast<int>(n); ++pass) {
        minimiseInBox(N, g, lower, upper, w);
        bool clash = false;
        for (std::size_t c = 0; c + 1 < n; c += 2)
            if (w[c] > 0.0 && w[c + 1] > 0.0) {
                upper[w[c] < w[c + 1] ? c : c + 1] = 0.0;
                clash = true;
            }
        if (!clash) break;
    }
    return w;
}

}  // namespace avatarbooth
