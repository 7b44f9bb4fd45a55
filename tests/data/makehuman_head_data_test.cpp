// The product's base head, made from MakeHuman's assets at build time (fit/head/makehuman_import.h): closed, its
// 68 feature vertices where dlib finds the landmarks on a render of it, and the jaw's on the face (the old head put
// four of them on the back of the head). tests/data/frmdb_fit_test.cpp fits the shared pairs with it.
#include "makehuman_head_required.h"
#include "test_paths.h"

#include "fit/face/landmarks68.h"
#include "fit/head/base_head.h"
#include "render/mesh_renderer.h"
#include "common/landmark_names.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <tuple>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

// Welded vertex ids (the UV seams' copies of a vertex are one point).
std::vector<std::uint32_t> welded(const Mesh& m) {
    std::map<std::tuple<double, double, double>, std::uint32_t> at;
    std::vector<std::uint32_t> id(m.positions.size());
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
        const auto& p = m.positions[v];
        id[v] = at.emplace(std::make_tuple(p.x, p.y, p.z), static_cast<std::uint32_t>(at.size())).first->second;
    }
    return id;
}

}  // namespace

TEST(MakeHumanHead, IsClosedAndCarriesItsModifiersAndSkin) {
    REQUIRE_MAKEHUMAN_HEAD();
    const BaseHead& head = *productBaseHead();
    const Mesh& m = head.mesh;
    std::printf("MakeHuman head: %zu vertices, %zu triangles, %zu modifiers\n", m.vertexCount(), m.triangles.size(),
                head.modifiers ? head.modifiers->modifiers.size() : 0);
    // Closed: every edge (seams welded) is shared by exactly two triangles, running opposite ways.
    const auto id = welded(m);
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (const auto& t : m.triangles)
        for (int k = 0; k < 3; ++k) ++directed[{id[t[k]], id[t[(k + 1) % 3]]}];
    int open = 0, twisted = 0;
    for (const auto& [e, n] : directed) {
        const auto back = directed.find({e.second, e.first});
        if (back == directed.end()) ++open;
        else if (n != 1 || back->second != 1) ++twisted;
    }
    EXPECT_EQ(open, 0) << "edges on an opening";
    EXPECT_EQ(twisted, 0) << "edges used more than once the same way";
    // Outwards: the signed volume of a closed mesh with outward normals is positive (and a head's, a few litres).
    double volume = 0.0;
    for (const auto& t : m.triangles)
        volume += glm::dot(m.positions[t.x], glm::cross(m.positions[t.y], m.positions[t.z])) / 6.0;
    EXPECT_GT(volume, 3.0e6);
    EXPECT_LT(volume, 8.0e6);
    // UVs inside the texture; the basis has the face groups and the macro directions; the skin is there.
    for (const auto& uv : m.uvs) {
        ASSERT_GE(uv.x, 0.0);
        ASSERT_LE(uv.x, 1.0);
        ASSERT_GE(uv.y, 0.0);
        ASSERT_LE(uv.y, 1.0);
    }
    ASSERT_TRUE(head.modifiers);
    std::set<std::string> groups;
    for (const auto& mod : head.modifiers->modifiers) groups.insert(mod.group);
    for (const char* g : {"head", "forehead", "eyebrows", "neck", "eyes", "nose", "mouth", "ears", "chin", "cheek", "macro"})
        EXPECT_TRUE(groups.count(g)) << g;
    for (const char* name : {"macro/gender-male", "macro/gender-female", "macro/age-old", "macro/weight-max",
                             "macro/muscle-min", "macro/african", "macro/asian", "macro/caucasian", "nose/nose-trans-vert-up"})
        EXPECT_LT(head.modifiers->find(name), head.modifiers->modifiers.size()) << name;
    EXPECT_FALSE(head.skin.empty());
    EXPECT_EQ(head.rigidParts.size(), 2u);  // the eyeballs
    EXPECT_EQ(head.frontFeatures.size(), 68u);
}

// The neck's cut edge is smooth, not a saw of whole quads: its vertices lie on the cut surface, level within 5 cm of
// the midline and rising 1.5 mm per mm beyond (MakeHumanImportOptions::neckCutDm), to the hundredth of a millimetre.
TEST(MakeHumanHead, NeckEdgeLiesOnTheCutSurface) {
    REQUIRE_MAKEHUMAN_HEAD();
    const Mesh& m = productBaseHead()->mesh;
    // The caps are fans: their centres have far more neighbours than any vertex of the surface; the neck's is lowest.
    std::map<std::uint32_t, std::set<std::uint32_t>> neighbours;
    for (const auto& t : m.triangles)
        for (int k = 0; k < 3; ++k) neighbours[t[k]].insert(t[(k + 1) % 3]);
    std::optional<std::uint32_t> neck;
    for (const auto& [v, n] : neighbours)
        if (n.size() > 20 && (!neck || m.positions[v].y < m.positions[*neck].y)) neck = v;
    ASSERT_TRUE(neck);
    const std::set<std::uint32_t>& edge = neighbours[*neck];
    ASSERT_GT(edge.size(), 30u);
    double level = 1e9;
    for (const auto v : edge) level = std::min(level, m.positions[v].y);
    int flat = 0;
    for (const auto v : edge) {
        const glm::dvec3& p = m.positions[v];
        EXPECT_NEAR(p.y - level, 1.5 * std::max(0.0, std::abs(p.x) - 50.0), 0.01) << "x " << p.x << " z " << p.z;
        flat += std::abs(p.x) < 50.0;
    }
    EXPECT_GT(flat, 10);  // front and back of the neck
    // Nor does it step in and out across the quads where the cut rises (behind the ears): there it made a spike 10 mm
    // high whose cap triangle faced sideways (normal y 0.05), a light triangle at the back of every avatar's neck.
    // Every cap triangle faces down, and the edge's height bends by under 3 mm from one vertex to the next.
    std::map<std::uint32_t, std::uint32_t> next;  // round the cap, as its triangles (centre, a, b) run
    for (const auto& t : m.triangles)
        for (int k = 0; k < 3; ++k)
            if (t[k] == *neck) {
                const glm::dvec3 a = m.positions[t[(k + 1) % 3]] - m.positions[*neck];
                const glm::dvec3 b = m.positions[t[(k + 2) % 3]] - m.positions[*neck];
                EXPECT_LT(glm::normalize(glm::cross(a, b)).y, -0.5) << "a cap triangle at x " << m.positions[t[(k + 1) % 3]].x;
                next[t[(k + 1) % 3]] = t[(k + 2) % 3];
            }
    ASSERT_EQ(next.size(), edge.size());
    double bend = 0.0;
    for (const auto& [v, after] : next) {
        const auto before = std::find_if(next.begin(), next.end(), [&](const auto& e) { return e.second == v; });
        ASSERT_NE(before, next.end());
        bend = std::max(bend, std::abs(m.positions[v].y - 0.5 * (m.positions[before->first].y + m.positions[after].y)));
    }
    EXPECT_LT(bend, 3.0);
}

TEST(MakeHumanHead, FeatureVerticesAreOnTheFaceWhereTheFrontViewSeesThem) {
    REQUIRE_MAKEHUMAN_HEAD();
    const BaseHead& head = *productBaseHead();
    const Mesh& m = head.mesh;
    // For each of the 68: no surface lies more than 3 mm in front of it along +z at its (x, y) (the eyeball bulges up
    // to 2.5 mm past the lid margin), and it is in front of the ear holes (the old head's jaw points 2, 3, 13, 14
    // were at z = -95 mm, on the back; the jaw's ends, beside the ears, are at least 15 mm in front of them).
    for (int k = 0; k < 68; ++k) {
        const glm::dvec3 p = m.positions[head.frontFeatures.at(landmarkName(k))];
        EXPECT_GT(p.z, head.earHoleCentre.z + (k <= 16 ? 15.0 : 30.0)) << landmarkName(k);
        double frontMost = -1e9;
        for (const auto& t : m.triangles) {
            const glm::dvec3 a = m.positions[t.x], b = m.positions[t.y], c = m.positions[t.z];
            const double d = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
            if (std::abs(d) < 1e-12) continue;
            const double u = ((p.x - a.x) * (c.y - a.y) - (c.x - a.x) * (p.y - a.y)) / d;
            const double v = ((b.x - a.x) * (p.y - a.y) - (p.x - a.x) * (b.y - a.y)) / d;
            if (u < 0 || v < 0 || u + v > 1) continue;
            frontMost = std::max(frontMost, a.z + u * (b.z - a.z) + v * (c.z - a.z));
        }
        EXPECT_LT(frontMost - p.z, 3.0) << landmarkName(k) << " is hidden behind the surface";
    }
}

TEST(MakeHumanHead, FeatureVerticesSitWhereDlibFindsTheLandmarksOnARenderOfIt) {
    REQUIRE_MAKEHUMAN_HEAD();
    const BaseHead& head = *productBaseHead();
    const Mesh& m = head.mesh;
    const double mmPerPixel = 0.3;
    const glm::dvec3 eye = head.eyeMidpoint();
    MeshRenderer renderer;
    RenderCamera camera = RenderCamera::orthographic(eye + glm::dvec3(0, -30, 800), eye + glm::dvec3(0, -30, 0),
                                                     {0, 1, 0}, mmPerPixel, 900, 1100);
    camera.background = cv::Scalar(140, 140, 140);
    renderer.upload(m, head.skin);
    cv::Mat image = renderer.render(camera).bgr.clone();
    // The skin paints the eyeballs white: an iris and a pupil where each looks out (its most forward point).
    for (const auto& part : head.rigidParts) {
        glm::dvec3 front(0.0, 0.0, -1e9);
        for (const auto v : part)
            if (m.positions[v].z > front.z) front = m.positions[v];
        const glm::dvec2 c = camera.project(front);
        const cv::Point centre(static_cast<int>(c.x), static_cast<int>(c.y));
        cv::circle(image, centre, static_cast<int>(5.5 / mmPerPixel), cv::Scalar(40, 70, 110), cv::FILLED, cv::LINE_AA);
        cv::circle(image, centre, static_cast<int>(2.0 / mmPerPixel), cv::Scalar(10, 10, 10), cv::FILLED, cv::LINE_AA);
    }
    cv::imwrite((test::scratchDir("makehuman_head") / "front_render.png").string(), image);
    const LandmarkDetector detector(AVATARBOOTH_DEFAULT_DLIB_MODEL);
    const FaceLandmarks found = detector.detect(image);
    ASSERT_EQ(found.facesFound, 1);
    double worst = 0.0, sum = 0.0;
    for (int k = 0; k < 68; ++k) {
        const glm::dvec2 q = camera.project(m.positions[head.frontFeatures.at(landmarkName(k))]);
        const double mm = std::hypot(q.x - 0.5 - found.points[static_cast<std::size_t>(k)].x,
                                     q.y - 0.5 - found.points[static_cast<std::size_t>(k)].y) * mmPerPixel;
        // Within a vertex spacing (the jaw's vertices are up to 9 mm apart); the detector's own scatter on the
        // same face is about a millimetre.
        EXPECT_LT(mm, k <= 16 ? 9.0 : 6.0) << landmarkName(k);
        worst = std::max(worst, mm);
        sum += mm * mm;
    }
    std::printf("MakeHuman head: feature vertices against a fresh detection: RMS %.2f mm, worst %.2f mm\n",
                std::sqrt(sum / 68.0), worst);
}
