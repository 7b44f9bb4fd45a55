// Small geometric helpers on Mesh (fit/head/mesh.h).
#include "fit/head/mesh.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace avatarbooth;

// Two squares one behind the other, the front one tilted: the front-most surface's z is interpolated, and a line
// along z past both is NaN.
TEST(Mesh, FrontZIsTheFrontMostSurfaceAlongZ) {
    Mesh m;
    m.positions = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0},    // behind, z 0
                   {0, 0, 5}, {10, 0, 15}, {10, 10, 15}, {0, 10, 5}};  // in front, z 5 + x
    m.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
    EXPECT_NEAR(m.frontZ(2.0, 3.0), 7.0, 1e-12);
    EXPECT_NEAR(m.frontZ(7.5, 9.0), 12.5, 1e-12);
    EXPECT_TRUE(std::isnan(m.frontZ(11.0, 5.0)));
    m.triangles.resize(2);
    EXPECT_NEAR(m.frontZ(2.0, 3.0), 0.0, 1e-12);
}
