// Integration test of the tile stage: the shipped sample map builds, and a box renders with the expected coverage.
#include "render/mesh_renderer.h"
#include "reveal/stage/tile_stage.h"

#include <gtest/gtest.h>

namespace avatarbooth::stage {
namespace {

TEST(StageRender, SampleMapBuildsHousePondAndStairs) {
    const Stage s = buildStage(loadTileMap(AVATARBOOTH_TEST_SOURCE_DIR "/app/assets/stage.map"));
    EXPECT_EQ(s.roofs.size(), 1u);
    const auto count = [&](StageBox::Kind kind) {
        return std::count_if(s.boxes.begin(), s.boxes.end(), [&](const StageBox& b) { return b.kind == kind; });
    };
    EXPECT_EQ(count(StageBox::Kind::House), 1);
    EXPECT_EQ(count(StageBox::Kind::PondFloor), 1);
    EXPECT_EQ(s.groups.size(), 3u);  // the ground and the two steps cut apart by the edge
}

TEST(StageRender, BoxCoversItsFootprintFromAboveAndItsFrontFromAhead) {
    cv::Mat palette;
    const Mesh mesh = stageMesh(buildStage(parseTileMap("ggg\nggg\nbbb\n")), 100.0, palette);
    MeshRenderer renderer;
    renderer.upload(mesh, palette);
    // 5 mm per pixel: a tile is 20 px. From above the box shows 3 x 2 tiles, from ahead 3 x 1.
    RenderCamera top = RenderCamera::orthographic({0, 2000, 0}, {0, 0, 0}, {0, 0, -1}, 5.0, 160, 120);
    top.lit = false;
    const RenderResult above = renderer.render(top);
    EXPECT_NEAR(cv::sum(above.mask)[0] / 255.0, 60.0 * 40.0, 60.0 * 40.0 * 0.03);
    const cv::Vec3b centre = above.bgr.at<cv::Vec3b>(60, 80);
    EXPECT_EQ(centre, palette.at<cv::Vec3b>(0, 0));  // the green top
    RenderCamera ahead = RenderCamera::orthographic({0, 50, 2000}, {0, 50, 0}, {0, 1, 0}, 5.0, 160, 120);
    ahead.lit = false;
    const RenderResult front = renderer.render(ahead);
    EXPECT_NEAR(cv::sum(front.mask)[0] / 255.0, 60.0 * 20.0, 60.0 * 20.0 * 0.03);
    EXPECT_EQ(front.bgr.at<cv::Vec3b>(60, 80), palette.at<cv::Vec3b>(0, 1));  // the brown front
}

}  // namespace
}  // namespace avatarbooth::stage
