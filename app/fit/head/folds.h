// Folds: triangles a warp turned over. The fit's second step must leave none (issue 21; counted as
// ../shared/tools/likeness/folds.py counts them: the normal turned by more than 90 degrees against the head before
// the warp, same topology).
#pragma once

#include "fit/head/mesh.h"

#include <cstddef>
#include <vector>

namespace avatarbooth {

// Indices of the triangles of `after` whose normal points more than 90 degrees away from the same triangle's in
// `before` (degenerate triangles of `before` are not counted).
std::vector<std::size_t> foldedTriangles(const Mesh& before, const Mesh& after);

// Removes the folds of a displacement field on `before` (after = before + displacement): the displacement at the
// folded triangles' vertices and their neighbours is replaced by its neighbours' mean, a ring wider each round, and
// as a last resort the whole field is scaled down until nothing folds. Vertices at the same position (UV seams)
// move as one. Returns how many triangles were folded before.
std::size_t unfold(const Mesh& before, Mesh& after, int maxRounds = 30);

}  // namespace avatarbooth
