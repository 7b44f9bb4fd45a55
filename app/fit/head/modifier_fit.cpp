// Bounded ridge least squares for the modifier weights (modifier_fit.h), solved on the normal equations by
// projected Newton steps (Bertsekas, "Projected Newton methods for optimization problems with simple constraints",
// SIAM J. Control Optim. 20(2), 1982): a few hundred unknowns, so the dense system is small; each step solves the
// free variables' system exactly (dlib's Cholesky) and projects onto the box, so the set of weights held at 0 or 1
// changes by many at once and the exact optimum is reached in a handful of steps, where coordinate descent needed
// hundreds of sweeps and stopped short of it.
#include "fit/head/modifier_fit.h"

#include <dlib/matrix.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace avatarbooth {
namespace {

// A target's two rows as directions in the view's plane, each scaled by the square root of its weight: the axes
// (a, b) for a point, the outline's normal and nothing for an outline point.
std::pair<glm::dvec2, glm::dvec2> rowDirections(const ModifierTarget& t) {
    if (glm::dot(t.normal, t.normal) > 0.0) {
        const glm::dvec2 n = glm::normalize(t.normal);
        return {std::sqrt(t.weight.x) * n, std::sqrt(t.weight.y) * glm::dvec2(-n.y, n.x)};
    }
    return {glm::dvec2(std::sqrt(t.weight.x), 0.0), glm::dvec2(0.0, std::sqrt(t.weight.y))};
}

// The indices of x's nonzero elements. Most modifiers sit at their bound 0, so the sums below run over these alone:
// the terms left out are exact zeros, and the sums are the same to the last bit.
void nonzeroIndices(const std::vector<double>& x, std::vector<std::size_t>& out) {
    out.clear();
    for (std::size_t j = 0; j < x.size(); ++j)
        if (x[j] != 0.0) out.push_back(j);
}

// 1/2 x^T N x - g^T x, N dense n x n row-major.
double objective(const std::vector<double>& N, const std::vector<double>& g, const std::vector<double>& x,
                 std::vector<std::size_t>& nonzero) {
    const std::size_t n = x.size();
    nonzeroIndices(x, nonzero);
    double f = 0.0;
    for (const std::size_t i : nonzero) {
        double s = 0.0;
        for (const std::size_t j : nonzero) s += N[i * n + j] * x[j];
        f += x[i] * (0.5 * s - g[i]);
    }
    return f;
}

// A variable at a bound whose gradient pushes it outwards is held there; Newton's step for the others is projected
// onto the box and halved until it decreases the objective enough (Armijo along the projection arc).
}  // namespace

void minimiseInBox(const std::vector<double>& N, const std::vector<double>& g, const std::vector<double>& lo,
                   const std::vector<double>& hi, std::vector<double>& x, int maxSteps) {
    const std::size_t n = x.size();
    for (std::size_t i = 0; i < n; ++i) x[i] = std::clamp(x[i], lo[i], hi[i]);
    std::vector<std::size_t> nonzero;
    double f = objective(N, g, x, nonzero);
    std::vector<double> gradient(n), next(n);
    std::vector<std::size_t> free;
    for (int step = 0; step < maxSteps; ++step) {
        free.clear();
        nonzeroIndices(x, nonzero);
        double largest = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            double s = -g[i];
            for (const std::size_t j : nonzero) s += N[i * n + j] * x[j];
            gradient[i] = s;
            if ((x[i] <= lo[i] && s >= 0.0) || (x[i] >= hi[i] && s <= 0.0)) continue;
            free.push_back(i);
            largest = std::max(largest, std::abs(s));
        }
        if (largest < 1e-9) return;  // the projected gradient vanishes: optimal
        const long m = static_cast<long>(free.size());
        dlib::matrix<double> Nf(m, m);
        dlib::matrix<double, 0, 1> minusGradient(m);
        for (long a = 0; a < m; ++a) {
            for (long b = 0; b < m; ++b) Nf(a, b) = N[free[a] * n + free[b]];
            minusGradient(a) = -gradient[free[a]];
        }
        const dlib::matrix<double, 0, 1> d = dlib::cholesky_decomposition<dlib::matrix<double>>(Nf).solve(minusGradient);
        double alpha = 1.0, fNext = f;
        for (int halving = 0; halving < 40; ++halving, alpha *= 0.5) {
            next = x;
            double decrease = 0.0;
            for (long a = 0; a < m; ++a) {
                const std::size_t i = free[a];
                next[i] = std::clamp(x[i] + alpha * d(a), lo[i], hi[i]);
                decrease += gradient[i] * (next[i] - x[i]);
            }
            fNext = objective(N, g, next, nonzero);
            if (fNext <= f + 1e-4 * decrease) break;
        }
        if (!(fNext < f)) return;  // no step decreases it any more (rounding)
        x.swap(next);
        f = fNext;
    }
}


std::vector<std::pair<std::size_t, std::size_t>> mirroredModifiers(const ModifierBasis& basis) {
    std::vector<std::pair<std::size_t, std::size_t>> pairs;
    for (std::size_t k = 0; k < basis.modifiers.size(); ++k) {
        const std::string& name = basis.modifiers[k].name;
        const std::string other = mirroredModifierName(name);
        const std::size_t j = basis.find(other);
        if (other < name && j < basis.modifiers.size()) pairs.emplace_back(k, j);  // from the "r-" side: each pair once
    }
    return pairs;
}

ModifierFit fitModifiers(const ModifierBasis& basis, const std::vector<glm::dvec3>& basePositions, const glm::dvec3& scale,
                         const glm::dvec3& centre, const std::vector<ModifierTarget>& targets,
                         const ModifierFitOptions& options) {
    const std::size_t K = basis.modifiers.size();
    const std::size_t n = K + 4;  // the weights, then t_x, t_y, t_z, sigma
    const std::size_t rows = 2 * targets.size();
    // Residuals at w = 0 and the design matrix, row-major rows x n.
    std::vector<double> r0(rows), A(rows * n, 0.0);
    std::multimap<std::uint32_t, std::size_t> rowsOf;  // vertex -> its targets
    for (std::size_t i = 0; i < targets.size(); ++i) {
        const ModifierTarget& t = targets[i];
        rowsOf.emplace(t.vertex, i);
        const glm::dvec3 p = centre + scale * (basePositions.at(t.vertex) - centre);
        const glm::dvec2 now = projectToView(p, t.view);
        // Each row measures the error along one direction of the view's plane, scaled by the square root of its
        // weight: the plane's axes, or the outline's normal alone.
        const auto [e0, e1] = rowDirections(t);
        const glm::dvec2 d = t.target - now;
        r0[2 * i] = glm::dot(e0, d);
        r0[2 * i + 1] = glm::dot(e1, d);
        const glm::dvec2 fromCentre = projectToView(p - centre, t.view);  // what sigma = 1 adds
        for (const auto& [row, e] : {std::pair{2 * i, e0}, std::pair{2 * i + 1, e1}}) {
            A[row * n + K + (t.view == View::Front ? 0 : 2)] = e.x;  // t_x moves front a, t_z side a
            A[row * n + K + 1] = e.y;                                 // t_y moves b in both
            A[row * n + K + 3] = glm::dot(e, fromCentre);
        }
    }
    for (std::size_t k = 0; k < K; ++k) {
        const Modifier& m = basis.modifiers[k];
        for (std::size_t j = 0; j < m.vertices.size(); ++j) {
            const auto range = rowsOf.equal_range(m.vertices[j]);
            for (auto it = range.first; it != range.second; ++it) {
                const auto [e0, e1] = rowDirections(targets[it->second]);
                const glm::dvec2 d = projectToView(scale * glm::dvec3(m.offsets[j]), targets[it->second].view);
                A[(2 * it->second) * n + k] += glm::dot(e0, d);
                A[(2 * it->second + 1) * n + k] += glm::dot(e1, d);
            }
        }
    }
    std::vector<bool> fixed(n, false);
    for (std::size_t k = 0; k < K; ++k)
        fixed[k] = std::find(options.fixedGroups.begin(), options.fixedGroups.end(), basis.modifiers[k].group) !=
                   options.fixedGroups.end();
    // Iteratively reweighted least squares (Huber): after each solve a target whose error exceeds robustMm counts
    // with weight robustMm / error, so that one misplaced point (a chin found on the lip) cannot bend the head.
    // The box: modifiers within their slider range (held ones at 0), the translation free, the size within its range.
    std::vector<double> lower(n, -std::numeric_limits<double>::infinity()), upper(n, std::numeric_limits<double>::infinity());
    for (std::size_t k = 0; k < K; ++k) {
        lower[k] = 0.0;
        upper[k] = fixed[k] ? 0.0 : 1.0;
    }
    lower[K + 3] = -std::max(0.0, options.scaleRange);
    upper[K + 3] = std::max(0.0, options.scaleRange);
    std::vector<double> w(n, 0.0), rowWeight(rows, 1.0);
    const std::vector<std::pair<std::size_t, std::size_t>> mirrorPairs = mirroredModifiers(basis);
    const double mu = options.mirrorRegularisation;
    const int solves = options.robustMm > 0.0 ? 1 + options.robustIterations : 1;
    for (int solve = 0; solve < solves; ++solve) {
        if (solve > 0)
            for (std::size_t i = 0; i < targets.size(); ++i) {
                double e2 = 0.0;
                for (const std::size_t r : {2 * i, 2 * i + 1}) {
                    double pred = 0.0;
                    for (std::size_t j = 0; j < n; ++j) pred += A[r * n + j] * w[j];
                    e2 += (r0[r] - pred) * (r0[r] - pred);
                }
                const double e = std::sqrt(e2);
                rowWeight[2 * i] = rowWeight[2 * i + 1] = e > options.robustMm ? options.robustMm / e : 1.0;
            }
        // Normal equations N w = g.
        std::vector<double> N(n * n, 0.0), g(n, 0.0);
        for (std::size_t r = 0; r < rows; ++r) {
            const double* a = &A[r * n];
            const double rw = rowWeight[r];
            for (std::size_t i = 0; i < n; ++i) {
                if (a[i] == 0.0) continue;
                g[i] += rw * a[i] * r0[r];
                for (std::size_t j = i; j < n; ++j) N[i * n + j] += rw * a[i] * a[j];
            }
        }
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = 0; j < i; ++j) N[i * n + j] = N[j * n + i];
        for (std::size_t k = 0; k < K; ++k) {
            const auto group = options.groupRegularisation.find(basis.modifiers[k].group);
            N[k * n + k] += group != options.groupRegularisation.end() ? group->second : options.regularisation;
        }
        for (const auto& [right, left] : mirrorPairs) {  // mu (w_right - w_left)^2
            N[right * n + right] += mu;
            N[left * n + left] += mu;
            N[right * n + left] -= mu;
            N[left * n + right] -= mu;
        }
        for (std::size_t i = K; i < n; ++i) N[i * n + i] += 1e-9;
        N[(K + 3) * n + K + 3] += options.scaleRegularisation;
        minimiseInBox(N, g, lower, upper, w, options.maxNewtonSteps);
    }
    ModifierFit fit;
    fit.weights.assign(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(K));
    fit.translation = {w[K], w[K + 1], w[K + 2]};
    fit.scaleChange = w[K + 3];
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
