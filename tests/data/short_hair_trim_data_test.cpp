// Short hair trimmed to the photos (fit/parts/hair_part.h trimShortHairToPhotos) against synthetic MakeHuman people
// whose short hair is known: the population's short cuts are painted on the scalp (sim/makehuman_visitor.h), each
// with its own hairline round the head (temples, a fade over the ears, the nape). Each short-haired person is fitted
// as the booth does, with the trim and without it, and the head's vertices the avatar's hair part covers are compared
// with the vertices the painted cut covers on the person's own head (same topology): intersection over union.
// Prints each person's figures; asserts what held with margin when it was written. Needs the product's base head.
#include "face_shape_error.h"
#include "test_paths.h"

#include "common/error.h"
#include "fit/fit_pipeline.h"
#include "sim/makehuman_visitor.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace avatarbooth;
using avatarbooth::test::median;

namespace {

constexpr unsigned kShortHairPeople = 60;
// A head vertex is under the avatar's hair when the hair part's surface lies this near it (short04 lies within about
// 2 mm of the scalp, its strand cards layered over it).
constexpr double kCoveredMm = 6.0;

cv::Vec3d paintAt(const cv::Mat& texture, const glm::dvec2& uv) {
    const int x = std::clamp(static_cast<int>(uv.x * texture.cols), 0, texture.cols - 1);
    const int y = std::clamp(static_cast<int>(uv.y * texture.rows), 0, texture.rows - 1);
    const cv::Vec3b c = texture.at<cv::Vec3b>(y, x);
    return {static_cast<double>(c[0]), static_cast<double>(c[1]), static_cast<double>(c[2])};
}

// The vertices of the person's head painted with hair: most of the triangles round the vertex are painted nearer
// the hair's colour than the skin's at their middle (a vertex's own UV can lie on an island's edge), the skin's read
// at the jaw's feature vertices (ibug 2-3 and 13-14).
std::vector<bool> paintedHair(const BaseHead& base, const MakeHumanVisitor& person) {
    const Mesh& m = person.photos.truthMesh;
    cv::Vec3d skin(0, 0, 0);
    for (const int k : {2, 3, 13, 14}) skin += paintAt(person.photos.texture, m.uvs[base.frontFeatures.at(cv::format("ibug_%02d", k))]);
    skin /= 4.0;
    std::vector<int> hairVotes(m.positions.size(), 0), votes(m.positions.size(), 0);
    for (const glm::uvec3& t : m.triangles) {
        const cv::Vec3d c = paintAt(person.photos.texture, (m.uvs[t.x] + m.uvs[t.y] + m.uvs[t.z]) / 3.0);
        const bool hair = cv::norm(c - person.person.hairColour) < cv::norm(c - skin);
        for (int k = 0; k < 3; ++k) {
            hairVotes[t[k]] += hair;
            ++votes[t[k]];
        }
    }
    std::vector<bool> hair(m.positions.size(), false);
    for (std::size_t v = 0; v < hair.size(); ++v) hair[v] = 2 * hairVotes[v] > votes[v];
    return hair;
}

// Distance from p to the triangle abc (Ericson, Real-Time Collision Detection, 5.1.5).
double distanceToTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return glm::length(ap);
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return glm::length(bp);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return glm::distance(p, a + ab * (d1 / (d1 - d3)));
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return glm::length(cp);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return glm::distance(p, a + ac * (d2 / (d2 - d6)));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
        return glm::distance(p, b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    const double denom = 1.0 / (va + vb + vc);
    return glm::distance(p, a + ab * (vb * denom) + ac * (vc * denom));
}

// The fitted head's vertices that the avatar's hair part covers: its surface lies within kCoveredMm.
std::vector<bool> coveredByHairPart(const FitOutcome& o) {
    std::vector<bool> covered(o.fit.mesh.positions.size(), false);
    for (const AvatarPart& part : o.parts) {
        if (part.name != "hair") continue;
        const auto& h = part.mesh.positions;
        for (std::size_t v = 0; v < covered.size(); ++v) {
            const glm::dvec3& p = o.fit.mesh.positions[v];
            for (const glm::uvec3& t : part.mesh.triangles)
                if (distanceToTriangle(p, h[t.x], h[t.y], h[t.z]) < kCoveredMm) {
                    covered[v] = true;
                    break;
                }
        }
    }
    return covered;
}

// The scalp, where the comparison is made: the head's vertices over the nape's bottom, not on the face (in front of
// the jaw's top under the brows), the ears or the neck. The painted cut has no brows, ears or beard in it; the hair
// part lies beside the ears.
std::vector<bool> scalpOf(const BaseHead& base, const Mesh& head) {
    const auto at = [&](int k) { return head.positions[base.frontFeatures.at(cv::format("ibug_%02d", k))]; };
    const double browY = std::max(at(19).y, at(24).y), jawZ = 0.5 * (at(0).z + at(16).z);
    std::vector<bool> scalp(head.positions.size(), false);
    for (std::size_t v = 0; v < scalp.size(); ++v) {
        const glm::dvec3& p = head.positions[v];
        const bool face = p.z > jawZ - 5.0 && p.y < browY + 10.0;
        const bool ear = std::abs(p.x) > 50.0 && std::hypot(p.y, p.z) < 40.0;
        scalp[v] = p.y > -40.0 && !face && !ear;
    }
    return scalp;
}

double coverageIou(const std::vector<bool>& a, const std::vector<bool>& b, const std::vector<bool>& where) {
    std::size_t both = 0, either = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (!where[i]) continue;
        both += a[i] && b[i];
        either += a[i] || b[i];
    }
    return either == 0 ? 1.0 : static_cast<double>(both) / static_cast<double>(either);
}

}  // namespace

TEST(ShortHairTrim, TheHairPartCoversTheScalpThePhotosShowHaired) {
    if (findMakeHumanBaseHead().empty()) GTEST_SKIP() << "the MakeHuman base head was not built";
    const auto base = productBaseHead();
    FitSettings untrimmed;
    untrimmed.trimShortHair = false;
    const FitPipeline trimming{FitSettings{}, *base}, plain{untrimmed, *base};
    MeshRenderer renderer;
    std::vector<double> before, after;
    int worse = 0;
    std::printf("%4s  %-15s %7s %7s %6s\n", "seed", "hair", "untrim", "trimmed", "dE h/s");
    for (unsigned seed = 1; seed <= kShortHairPeople; ++seed) {
        MakeHumanVisitorOptions options;
        options.seed = seed;
        options.sideNoseImageRight = seed % 2 == 1;
        const MakeHumanVisitor person = makeMakeHumanVisitor(*base, renderer, options);
        if (person.person.hairStyle != "short") continue;
        const SyntheticVisitor& v = person.photos;
        try {
            const FitOutcome withTrim = trimming.fit(v.front, v.side, v.background);
            if (withTrim.hair.style != HairStyle::Short) continue;  // the analysis' style is HairPopulation's to judge
            const FitOutcome withoutTrim = plain.fit(v.front, v.side, v.background);
            const std::vector<bool> truth = paintedHair(*base, person), scalp = scalpOf(*base, v.truthMesh);
            const double b = coverageIou(truth, coveredByHairPart(withoutTrim), scalp);
            const double a = coverageIou(truth, coveredByHairPart(withTrim), scalp);
            before.push_back(b);
            after.push_back(a);
            worse += a < b - 0.02;
            std::printf("%4u  %-15s %7.3f %7.3f %6.1f\n", seed, person.person.hair.c_str(), b, a,
                        cv::norm(withTrim.hair.hairLab - withTrim.hair.skinLab));
        } catch (const BoothError& e) {
            std::printf("%4u  %-15s refused: %s\n", seed, person.person.hair.c_str(), e.what());
        }
    }
    std::printf("short hair over the painted cut (IoU of the head's vertices), median over %zu people: untrimmed "
                "%.3f, trimmed %.3f; %d worse by more than 0.02\n",
                after.size(), median(before), median(after), worse);
    ASSERT_GE(after.size(), 15u);
    EXPECT_GT(median(after), median(before) + 0.05);
    // Measured 2026-12-05: 0 worse (the blond 9, 28 and 46, whose light hair the colour model took partly for skin,
    // were, until kTrimMinHairSkinContrast left them their short04 whole).
    EXPECT_LE(worse, 2);
}
