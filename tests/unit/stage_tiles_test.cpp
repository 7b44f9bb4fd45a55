// Unit tests of the tile stage: the map format, every generation rule on a small map, the mesh and R(theta).
#include "common/error.h"
#include "reveal/stage/tile_stage.h"

#include <gtest/gtest.h>

#include <cmath>

namespace avatarbooth::stage {
namespace {

StageBox box(StageBox::Kind kind, int group, glm::dvec3 lo, glm::dvec3 hi) {
    StageBox b;
    b.kind = kind;
    b.group = group;
    b.min = lo;
    b.max = hi;
    return b;
}
StageBox ground(int group, glm::dvec3 lo, glm::dvec3 hi) { return box(StageBox::Kind::Ground, group, lo, hi); }

std::string describe(const std::vector<StageBox>& boxes) {
    std::string s;
    for (const StageBox& b : boxes)
        s += "kind " + std::to_string(static_cast<int>(b.kind)) + " group " + std::to_string(b.group) + " [" +
             std::to_string(b.min.x) + "," + std::to_string(b.min.y) + "," + std::to_string(b.min.z) + "]-[" +
             std::to_string(b.max.x) + "," + std::to_string(b.max.y) + "," + std::to_string(b.max.z) + "]\n";
    return s;
}

TEST(StageMap, ParsesTilesAndEdgeMarks) {
    const TileMap map = parseTileMap("# a comment\ng|gw\n  -\nbre  # trailing\n\nb\n");
    EXPECT_EQ(map.width, 3);
    EXPECT_EQ(map.height, 3);
    EXPECT_EQ(map.at(0, 0), Tile::Green);
    EXPECT_EQ(map.at(2, 0), Tile::Blue);
    EXPECT_EQ(map.at(1, 1), Tile::Red);
    EXPECT_EQ(map.at(2, 1), Tile::Beige);
    EXPECT_EQ(map.at(1, 2), Tile::Empty);  // short row padded
    EXPECT_TRUE(map.edgeRight(0, 0));
    EXPECT_FALSE(map.edgeRight(1, 0));
    EXPECT_FALSE(map.edgeBelow(0, 0));
    EXPECT_TRUE(map.edgeBelow(1, 0));  // the '-' in character column 3 stands under the second tile of "g|gw"
}

TEST(StageMap, ErrorsNameFileLineAndColumn) {
    try {
        parseTileMap("gg\ngx\n", "stage.map");
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_EQ(e.where(), "stage.map:2:2");
    }
    try {
        parseTileMap("g|g\n -\ngg\n", "m");
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.where(), "m:2:2");  // the '-' stands under the '|', not under a tile
    }
    EXPECT_THROW(parseTileMap("|g\n"), BoothError);
    EXPECT_THROW(parseTileMap("g|\n"), BoothError);
    EXPECT_THROW(parseTileMap("gg\n--\n"), BoothError);  // nothing below the edge row
    EXPECT_THROW(parseTileMap("# only a comment\n"), BoothError);
}

TEST(StageRules, BasicBoxIsWidthHeightDepthOfItsTiles) {
    const Stage s = buildStage(parseTileMap("ggg\nggg\nbbb\n"));
    ASSERT_EQ(s.groups.size(), 1u);
    EXPECT_EQ(s.groups[0].height, 1);
    const std::vector<StageBox> expected{ground(0, {0, 0, 1}, {3, 1, 3})};  // W 3, H 1, D 2
    EXPECT_EQ(s.boxes, expected) << describe(s.boxes);
}

TEST(StageRules, BoxThatAppearsToSitOnAnotherIsRaisedOntoIt) {
    const Stage s = buildStage(parseTileMap(".g...\n.g...\n.b...\nggggg\nbbbbb\n"));
    ASSERT_EQ(s.groups.size(), 2u);
    EXPECT_EQ(s.groups[0].sitsOn, 1);
    EXPECT_EQ(s.groups[0].base, 1.0);
    const std::vector<StageBox> expected{ground(0, {1, 1, 2}, {2, 2, 4}), ground(1, {0, 0, 4}, {5, 1, 5})};
    EXPECT_EQ(s.boxes, expected) << describe(s.boxes);
}

TEST(StageRules, GroupTakesItsHighestBoxSoTheLowerOneFloatsUntilAnEdgeSplitsThem) {
    // Without the edge: one group, height 2; column 2's own box (1 brown) hangs from the top and floats.
    const Stage joined = buildStage(parseTileMap("gg.\nggg\nbbg\nbbb\n"));
    ASSERT_EQ(joined.groups.size(), 1u);
    EXPECT_EQ(joined.groups[0].height, 2);
    const std::vector<StageBox> floating{ground(0, {0, 0, 2}, {2, 2, 4}), ground(0, {2, 1, 3}, {3, 2, 5})};
    EXPECT_EQ(joined.boxes, floating) << describe(joined.boxes);
    // With the edge: two groups, each standing on the ground: stairs.
    const Stage stairs = buildStage(parseTileMap("gg.\ngg|g\nbbg\nbbb\n"));
    ASSERT_EQ(stairs.groups.size(), 2u);
    const std::vector<StageBox> steps{ground(0, {0, 0, 2}, {2, 2, 4}), ground(1, {2, 0, 2}, {3, 1, 4})};
    EXPECT_EQ(stairs.boxes, steps) << describe(stairs.boxes);
}

TEST(StageRules, EdgesMakeACubeOnASlabAndTheHiddenSlabIsCompleted) {
    // No edges: one group, a slab with a hole where the brown tile is.
    const Stage holed = buildStage(parseTileMap("ggggg\nggggg\nggbgg\nggggg\nbbbbb\n"));
    ASSERT_EQ(holed.groups.size(), 1u);
    const std::vector<StageBox> withHole{ground(0, {0, 0, 1}, {2, 1, 5}), ground(0, {2, 0, 1}, {3, 1, 3}),
                                         ground(0, {2, 0, 4}, {3, 1, 5}), ground(0, {3, 0, 1}, {5, 1, 5})};
    EXPECT_EQ(holed.boxes, withHole) << describe(holed.boxes);
    // Edges round the middle tile: a cube sitting on the slab, the slab whole beneath it.
    const Stage cube = buildStage(parseTileMap("ggggg\n  -\ngg|g|gg\nggbgg\nggggg\nbbbbb\n"));
    ASSERT_EQ(cube.groups.size(), 2u);
    const std::vector<StageBox> expected{ground(0, {0, 0, 1}, {5, 1, 5}), ground(1, {2, 1, 3}, {3, 2, 4})};
    EXPECT_EQ(cube.boxes, expected) << describe(cube.boxes);
    EXPECT_EQ(cube.groups[1].sitsOn, 0);
}

TEST(StageRules, RearBrownFaceSeenAboveANearerGroupReachesTheGroundUnlessAnEdgeCutsIt) {
    // A slab 2 high (rows 0-1 green, its front rows 2-3) with a cube 1 high in front of its middle (row 3 green, row
    // 4 its front). Columns 1-2 of the slab show one brown row and then the cube's green; the slab's brown group runs
    // on to row 3 in columns 0 and 3, so it is one face standing on the ground behind the cube.
    const Stage s = buildStage(parseTileMap("gggg\ngggg\nbbbb\nbggb\n.bb.\n"));
    ASSERT_EQ(s.groups.size(), 2u);
    EXPECT_EQ(s.groups[0].sitsOn, -1);
    EXPECT_EQ(s.groups[0].height, 2);
    EXPECT_EQ(s.groups[1].sitsOn, -1);
    const std::vector<StageBox> expected{ground(0, {0, 0, 2}, {4, 2, 4}), ground(1, {1, 0, 4}, {3, 1, 5})};
    EXPECT_EQ(s.boxes, expected) << describe(s.boxes);
    // Edge marks cut columns 1-2 of that brown row from the rest: their face ends on the cube's green, so (the
    // stacking rule) the slab sits on the cube: top 1 + 2 = 3, columns 0 and 3 keep their 2-tile front, 1-2 their 1.
    const Stage cut = buildStage(parseTileMap("gggg\ngggg\nb|bb|b\nbggb\n.bb.\n"));
    ASSERT_EQ(cut.groups.size(), 2u);
    EXPECT_EQ(cut.groups[0].sitsOn, 1);
    EXPECT_EQ(cut.groups[0].base, 1.0);
    const std::vector<StageBox> stacked{ground(0, {0, 1, 3}, {1, 3, 5}), ground(0, {1, 2, 3}, {3, 3, 5}),
                                        ground(0, {3, 1, 3}, {4, 3, 5}), ground(1, {1, 0, 4}, {3, 1, 5})};
    EXPECT_EQ(cut.boxes, stacked) << describe(cut.boxes);
}

TEST(StageRules, GroundBehindAHouseIsCompleted) {
    // A house in the middle of a green field: the field's columns 1-3 show green above the roof and below the walls;
    // the ground goes on behind the house, so the field is one whole slab, the house on it.
    const Stage s = buildStage(parseTileMap("ggggg\ngrrrg\ngrrrg\ngeeeg\ngeeeg\nggggg\nbbbbb\n"));
    ASSERT_EQ(s.groups.size(), 1u);
    EXPECT_EQ(s.groups[0].height, 1);
    const std::vector<StageBox> expected{ground(0, {0, 0, 1}, {5, 1, 7}),
                                         box(StageBox::Kind::House, -1, {1, 1, 4}, {4, 3, 6})};
    EXPECT_EQ(s.boxes, expected) << describe(s.boxes);
    ASSERT_EQ(s.roofs.size(), 1u);
    EXPECT_EQ(s.roofs[0].min, glm::dvec3(1, 3, 4));
    EXPECT_DOUBLE_EQ(s.roofs[0].max.y, 3 + 2 / std::sqrt(2.0));
    // A house standing on the ground (no green under its walls) completes nothing: the gap behind it stays.
    const Stage apart = buildStage(parseTileMap("ggg\nrrr\neee\n"));
    const std::vector<StageBox> noFill{ground(0, {0, 0, 0}, {3, 0, 1}),
                                       box(StageBox::Kind::House, -1, {0, 0, 2}, {3, 1, 3})};
    EXPECT_EQ(apart.boxes, noFill) << describe(apart.boxes);
}

TEST(StageRules, PondWithNoBrownWallIsWaterLevelWithTheGround) {
    // Green, blue, green: no brown wall shows, so no depth: the water fills the hole at the ground's top.
    const Stage s = buildStage(parseTileMap("ggg\ngwg\nggg\nbbb\n"));
    ASSERT_EQ(s.groups.size(), 1u);
    const std::vector<StageBox> expected{ground(0, {0, 0, 1}, {1, 1, 4}), ground(0, {1, 0, 1}, {2, 1, 2}),
                                         ground(0, {1, 0, 3}, {2, 1, 4}), ground(0, {2, 0, 1}, {3, 1, 4}),
                                         box(StageBox::Kind::PondFloor, 0, {1, 0, 2}, {2, 1, 3})};
    EXPECT_EQ(s.boxes, expected) << describe(s.boxes);
}

TEST(StageRules, PondDigsAsDeepAsItsBrownRun) {
    const Stage s = buildStage(parseTileMap("ggg\ngbg\ngwg\nggg\nbbb\nbbb\n"));
    ASSERT_EQ(s.groups.size(), 1u);
    EXPECT_EQ(s.groups[0].height, 2);
    const std::vector<StageBox> expected{
        ground(0, {0, 0, 2}, {1, 2, 6}), ground(0, {1, 0, 2}, {2, 2, 3}), ground(0, {1, 0, 5}, {2, 2, 6}),
        ground(0, {2, 0, 2}, {3, 2, 6}), box(StageBox::Kind::PondFloor, 0, {1, 0, 3}, {2, 1, 5})};
    EXPECT_EQ(s.boxes, expected) << describe(s.boxes);
}

TEST(StageRules, HouseOnGroundHasTheRootTwoRoof) {
    const Stage s = buildStage(parseTileMap(".rrr.\n.rrr.\n.eee.\n.eee.\nggggg\nbbbbb\n"));
    ASSERT_EQ(s.roofs.size(), 1u);
    const std::vector<StageBox> expected{ground(0, {0, 0, 5}, {5, 1, 6}),
                                         box(StageBox::Kind::House, -1, {1, 1, 3}, {4, 3, 5})};
    EXPECT_EQ(s.boxes, expected) << describe(s.boxes);
    EXPECT_EQ(s.roofs[0].min, glm::dvec3(1, 3, 3));
    EXPECT_DOUBLE_EQ(s.roofs[0].max.y, 3 + 2 / std::sqrt(2.0));
    EXPECT_EQ(s.roofs[0].max.x, 4);
    EXPECT_EQ(s.roofs[0].max.z, 5);
}

TEST(StageMesh, BoxesBecomeClosedColouredSolids) {
    cv::Mat palette;
    const Mesh mesh = stageMesh(buildStage(parseTileMap(".rr.\n.ee.\ngggg\nbbbb\n")), 100.0, palette);
    EXPECT_EQ(palette.cols, 5);
    // A ground box and a house box (6 quads each) and a roof (2 slopes, 2 gables, 1 underside).
    EXPECT_EQ(mesh.triangles.size(), 12u + 12u + 2u + 2u + 1u + 1u + 2u);
    glm::dvec3 lo, hi;
    mesh.bounds(lo, hi);
    EXPECT_DOUBLE_EQ(lo.y, 0.0);
    EXPECT_DOUBLE_EQ(hi.y, 100.0 * (2 + 1 / std::sqrt(2.0)));
    EXPECT_DOUBLE_EQ(hi.x - lo.x, 400.0);
    EXPECT_DOUBLE_EQ(lo.x, -200.0);
}

TEST(StageBlend, RFollowsBothBranches) {
    const double k = std::sqrt(2.0) - 1.0;
    EXPECT_DOUBLE_EQ(blendR(0.0), 1.0);
    EXPECT_DOUBLE_EQ(blendR(45.0), std::sqrt(2.0));
    EXPECT_DOUBLE_EQ(blendR(90.0), 1.0);
    EXPECT_DOUBLE_EQ(blendR(44.999), k * 44.999 / 45.0 + 1.0);  // first branch up to 45
    EXPECT_DOUBLE_EQ(blendR(30.0), k * 30.0 / 45.0 + 1.0);
    EXPECT_DOUBLE_EQ(blendR(60.0), k * 30.0 / 45.0 + 1.0);
    EXPECT_DOUBLE_EQ(blendR(-45.0), std::sqrt(2.0));              // second branch from -45
    EXPECT_DOUBLE_EQ(blendR(-10.0), k * 80.0 / 45.0 + 1.0);
    EXPECT_DOUBLE_EQ(blendR(-45.001), k * 45.001 / 45.0 + 1.0);  // first branch below -45
    EXPECT_DOUBLE_EQ(blendR(-89.0), k * 89.0 / 45.0 + 1.0);
    // Continuous across 45 and -45.
    EXPECT_NEAR(blendR(45.0 - 1e-9), blendR(45.0), 1e-9);
    EXPECT_NEAR(blendR(-45.0 - 1e-9), blendR(-45.0), 1e-9);
}

TEST(StageBlend, TransformStretchesAlongTheDiagonalOnly) {
    const glm::dmat4 m = blendTransform(45.0);
    const double r = std::sqrt(2.0);
    // The (0, 1, -1)/sqrt2 direction is what the 45-degree rotation turns into +y: scaled by R.
    const glm::dvec4 diag = m * glm::dvec4(0.0, 1.0, -1.0, 0.0);
    EXPECT_NEAR(diag.y, r, 1e-12);
    EXPECT_NEAR(diag.z, -r, 1e-12);
    // The perpendicular (0, 1, 1) direction and x are unchanged.
    const glm::dvec4 perp = m * glm::dvec4(0.0, 1.0, 1.0, 0.0);
    EXPECT_NEAR(perp.y, 1.0, 1e-12);
    EXPECT_NEAR(perp.z, 1.0, 1e-12);
    const glm::dvec4 x = m * glm::dvec4(1.0, 0.0, 0.0, 0.0);
    EXPECT_NEAR(x.x, 1.0, 1e-12);
    EXPECT_NEAR(glm::length(glm::dvec3(blendTransform(0.0) * glm::dvec4(0.3, 0.5, 0.7, 1.0)) - glm::dvec3(0.3, 0.5, 0.7)), 0.0, 1e-12);
}

}  // namespace
}  // namespace avatarbooth::stage
