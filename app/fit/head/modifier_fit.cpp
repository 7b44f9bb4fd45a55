// Bounded ridge least squares for the modifier weights (modifier_fit.h), solved on the normal equations by
// projected Gauss-Seidel: a few hundred unknowns and rows, so the dense system is small and each sweep is exact
// coordinate descent of a convex problem with box bounds.
#include "fit/head/modifier_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace avatarbooth {

ModifierFit fitModifiers(const ModifierBasis& basis, const std::vector<glm::dvec3>& basePositions, const glm::dvec3& scale,
                         const glm::dvec3& centre, const std::vector<ModifierTarget>& targets,
                         const ModifierFitOptions& options) {
    const std::size_t K = basis.modifiers.size();
    const std::size_t n = K + 3;  // the weights, then t_x, t_y, t_z
    const std::size_t rows = 2 * targets.size();
    // Residuals at w = 0 and the design matrix, row-major rows x n.
    std::vector<double> r0(rows), A(rows * n, 0.0);
    std::multimap<std::uint32_t, std::size_t> rowsOf;  // vertex -> its targets
    for (std::size_t i = 0; i < targets.size(); ++i) {
        const ModifierTarget& t = targets[i];
        rowsOf.emplace(t.vertex, i);
        const glm::dvec3 p = centre + scale * (basePositions.at(t.vertex) - centre);
        const glm::dvec2 now = projectToView(p, t.view);
        const glm::dvec2 sw = glm::sqrt(t.weight);  // rows scaled by the square roots of the weights
        r0[2 * i] = sw.x * (t.target.x - now.x);
        r0[2 * i + 1] = sw.y * (t.target.y - now.y);
        A[(2 * i) * n + K + (t.view == View::Front ? 0 : 2)] = sw.x;  // t_x moves front a, t_z side a
        A[(2 * i + 1) * n + K + 1] = sw.y;                              // t_y moves b in both
    }
    for (std::size_t k = 0; k < K; ++k) {
        const Modifier& m = basis.modifiers[k];
        for (std::size_t j = 0; j < m.vertices.size(); ++j) {
            const auto range = rowsOf.equal_range(m.vertices[j]);
            for (auto it = range.first; it != range.second; ++it) {
                const ModifierTarget& t = targets[it->second];
                const glm::dvec2 d = glm::sqrt(t.weight) * projectToView(scale * glm::dvec3(m.offsets[j]), t.view);
                A[(2 * it->second) * n + k] += d.x;
                A[(2 * it->second + 1) * n + k] += d.y;
            }
        }
    }
    // Normal equations N w = g.
    std::vector<double> N(n * n, 0.0), g(n, 0.0);
    for (std::size_t r = 0; r < rows; ++r) {
        const double* a = &A[r * n];
        for (std::size_t i = 0; i < n; ++i) {
            if (a[i] == 0.0) continue;
            g[i] += a[i] * r0[r];
            for (std::size_t j = i; j < n; ++j) N[i * n + j] += a[i] * a[j];
        }
    }
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < i; ++j) N[i * n + j] = N[j * n + i];
    for (std::size_t k = 0; k < K; ++k) N[k * n + k] += options.regularisation;
    for (std::size_t i = K; i < n; ++i) N[i * n + i] += 1e-9;
    std::vector<bool> fixed(n, false);
    for (std::size_t k = 0; k < K; ++k)
        fixed[k] = std::find(options.fixedGroups.begin(), options.fixedGroups.end(), basis.modifiers[k].group) !=
                   options.fixedGroups.end();
    std::vector<double> w(n, 0.0);
    for (int sweep = 0; sweep < options.sweeps; ++sweep) {
        double change = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            if (fixed[i] || N[i * n + i] <= 0.0) continue;
            double s = g[i];
            const double* row = &N[i * n];
            for (std::size_t j = 0; j < n; ++j) s -= row[j] * w[j];
            double next = w[i] + s / row[i];
            if (i < K) next = std::clamp(next, 0.0, 1.0);
            change = std::max(change, std::abs(next - w[i]));
            w[i] = next;
        }
        if (change < 1e-7) break;
    }
    ModifierFit fit;
    fit.weights.assign(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(K));
    fit.translation = {w[K], w[K + 1], w[K + 2]};
    double before = 0.0, after = 0.0;
    for (std::size_t r = 0; r < rows; ++r) {
        double pred = 0.0;
        for (std::size_t i = 0; i < n; ++i) pred += A[r * n + i] * w[i];
        before += r0[r] * r0[r];
        after += (r0[r] - pred) * (r0[r] - pred);
    }
    if (!targets.empty()) {
        fit.rmsBeforeMm = std::sqrt(before / static_cast<double>(targets.size()));
        fit.rmsAfterMm = std::sqrt(after / static_cast<double>(targets.size()));
    }
    return fit;
}

}  // namespace avatarbooth
