// Fold detection and removal.
#include "fit/head/folds.h"

#include <algorithm>
#include <map>
#include <set>
#include <tuple>

namespace avatarbooth {
namespace {

glm::dvec3 normal(const Mesh& m, const glm::uvec3& t) {
    return glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]);
}

// One id per distinct position (the UV seams' copies of a vertex share one), and each id's neighbours.
struct Welded {
    std::vector<std::uint32_t> id;
    std::vector<std::vector<std::uint32_t>> members, neighbours;

    explicit Welded(const Mesh& m) : id(m.positions.size()) {
        std::map<std::tuple<double, double, double>, std::uint32_t> at;
        for (std::uint32_t v = 0; v < m.positions.size(); ++v) {
            const auto& p = m.positions[v];
            const auto [it, added] = at.emplace(std::make_tuple(p.x, p.y, p.z), static_cast<std::uint32_t>(members.size()));
            if (added) members.emplace_back();
            id[v] = it->second;
            members[it->second].push_back(v);
        }
        std::vector<std::set<std::uint32_t>> n(members.size());
        for (const auto& t : m.triangles)
            for (int k = 0; k < 3; ++k) {
                const auto a = id[t[k]], b = id[t[(k + 1) % 3]];
                if (a != b) {
                    n[a].insert(b);
                    n[b].insert(a);
                }
            }
        for (const auto& s : n) neighbours.emplace_back(s.begin(), s.end());
    }
};

}  // namespace

std::vector<std::size_t> foldedTriangles(const Mesh& before, const Mesh& after) {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < before.triangles.size(); ++i) {
        const glm::dvec3 a = normal(before, before.triangles[i]);
        if (glm::dot(a, a) < 1e-18) continue;
        if (glm::dot(a, normal(after, before.triangles[i])) < 0.0) out.push_back(i);
    }
    return out;
}

std::size_t unfold(const Mesh& before, Mesh& after, int maxRounds) {
    std::vector<std::size_t> folded = foldedTriangles(before, after);
    const std::size_t first = folded.size();
    if (folded.empty()) return 0;
    const Welded w(before);
    std::vector<glm::dvec3> d(w.members.size());
    for (std::size_t i = 0; i < d.size(); ++i) d[i] = after.positions[w.members[i][0]] - before.positions[w.members[i][0]];
    const auto write = [&](double scale) {
        for (std::size_t i = 0; i < d.size(); ++i)
            for (const auto v : w.members[i]) after.positions[v] = before.positions[v] + scale * d[i];
    };
    std::vector<char> smooth(d.size(), 0);
    for (int round = 0; round < maxRounds && !folded.empty(); ++round) {
        // The folded triangles' vertices join the smoothed region, and the region grows by one ring.
        for (const auto t : folded)
            for (int k = 0; k < 3; ++k) smooth[w.id[before.triangles[t][k]]] = 1;
        std::vector<char> grown(smooth);
        for (std::size_t i = 0; i < d.size(); ++i)
            if (smooth[i])
                for (const auto n : w.neighbours[i]) grown[n] = 1;
        smooth.swap(grown);
        for (int pass = 0; pass < 4; ++pass) {
            std::vector<glm::dvec3> next(d);
            for (std::size_t i = 0; i < d.size(); ++i) {
                if (!smooth[i] || w.neighbours[i].empty()) continue;
                glm::dvec3 sum(0.0);
                for (const auto n : w.neighbours[i]) sum += d[n];
                next[i] = sum / static_cast<double>(w.neighbours[i].size());
            }
            d.swap(next);
        }
        write(1.0);
        folded = foldedTriangles(before, after);
    }
    // Last resort: less of the whole warp.
    for (double scale = 0.9; !folded.empty() && scale > 0.0; scale -= 0.1) {
        write(scale);
        folded = foldedTriangles(before, after);
    }
    if (!folded.empty()) write(0.0);
    return first;
}

}  // namespace avatarbooth
