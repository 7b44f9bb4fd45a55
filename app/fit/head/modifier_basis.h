// A base head's modifier basis: MakeHuman's targets (head shape, forehead, brows, eyes, nose, mouth, ears, chin,
// cheeks, neck, and the macro directions gender, age, weight, muscle, proportions and the three ethnic blends),
// restricted to the head's vertices. Each modifier is one-sided, as MakeHuman's own targets are ("nose-trans-up" and
// "nose-trans-down" are two): its weight runs from 0 (the average head) to 1 (the target fully applied), so a
// slider's two ends are two modifiers and the fit's bounds are simple boxes.
#pragma once

#include "fit/head/mesh.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace avatarbooth {

struct Modifier {
    std::string name;   // the target's name, e.g. "nose/nose-trans-up", "macro/gender-male"
    std::string group;  // MakeHuman's modifier group (head, nose, ..., macro)
    // The vertices it moves and by how much at weight 1 (millimetres, head space).
    std::vector<std::uint32_t> vertices;
    std::vector<glm::vec3> offsets;
};

struct ModifierBasis {
    std::size_t vertexCount = 0;  // of the base head it belongs to
    std::vector<Modifier> modifiers;

    // base + sum_k weights[k] * modifier k (weights.size() == modifiers.size()).
    std::vector<glm::dvec3> apply(const std::vector<glm::dvec3>& base, const std::vector<double>& weights) const;
    std::size_t find(const std::string& name) const;  // index, or modifiers.size() when there is none
};

// The subject's other side's modifier: "eyes/r-eye-bag-min" <-> "eyes/l-eye-bag-min"; a name without a side is its
// own mirror.
std::string mirroredModifierName(const std::string& name);

// The basis file: "ABMODBAS" magic, format version, vertex count, then each modifier's name, group and sparse
// offsets (little-endian). Written atomically; a truncated or foreign file is refused naming the file.
void saveModifierBasis(const ModifierBasis& basis, const std::filesystem::path& file);
ModifierBasis loadModifierBasis(const std::filesystem::path& file, std::size_t expectedVertexCount);

}  // namespace avatarbooth
