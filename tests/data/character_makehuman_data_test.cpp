// The character on the product's base head (MakeHuman's): Narita's proportions asked for come back when the
// character is measured as a photo is, its sliders are the basis's own modifiers within their ranges, exaggeration
// pushes away from the average head, and on real FRMDB photos the character is made and drawn beside the avatar.
#include "makehuman_head_required.h"
#include "test_paths.h"

#include "booth/session_folder.h"
#include "common/image_io.h"
#include "common/landmark_names.h"
#include "fit/fit_pipeline.h"
#include "render/mesh_renderer.h"
#include "render/previews.h"
#include "reveal/character/character_modifiers.h"
#include "reveal/character/character_outputs.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

const BaseHead& makeHuman() { return *productBaseHead(); }

CharacterSettings quick() {
    CharacterSettings s;
    s.textureSize = 64;  // the texture does not matter here
    return s;
}

const CharacterProportions& baseProportions() {
    static const CharacterProportions p = measureHead(makeHuman().mesh, makeHuman(), makeHuman().earHoleCentre).proportions;
    return p;
}

// How near a measured quantity must come to the one asked for. The head is measured on a 4 px/mm silhouette whose
// face width is about 150 mm (600 px): a point one pixel off moves a ratio by 0.0017, and a ratio takes two or
// three points, hence 0.005 for the eyes, brows, nose and mouth (feature vertices, projected exactly) and the face
// aspect. The ears' top and bottom are notches found on the silhouette, a few pixels wide: 0.01. Tilts: one pixel
// over an eye's 30 mm (120 px) width is half a degree, two points: 1 degree; a brow's 45 mm: 1 degree.
double tolerance(std::size_t i) {
    const std::string_view q = sliderRanges()[i].quantity;
    if (q == "r3" || q == "r4") return 0.01;
    if (q == "eye_tilt_deg" || q == "brow_tilt_deg") return 1.0;
    return 0.005;
}

// Prints base, asked and measured per quantity; returns how many are within their tolerance of the asked value.
int printReached(const char* what, const CharacterHead& head) {
    const QuantityVector asked = quantitiesOf(head.target), got = quantitiesOf(head.achieved),
                         was = quantitiesOf(head.base);
    std::printf("%s: quantity, base head, asked, measured\n", what);
    int within = 0;
    for (std::size_t i = 0; i < kCharacterQuantities; ++i) {
        const bool ok = std::abs(got[i] - asked[i]) <= tolerance(i);
        within += ok ? 1 : 0;
        std::printf("  %-14s %8.4f %8.4f %8.4f%s\n", std::string(sliderRanges()[i].quantity).c_str(), was[i], asked[i],
                    got[i], ok ? "" : "  (not reached)");
    }
    return within;
}

void printAndExpectReached(const char* what, const CharacterHead& head) {
    printReached(what, head);
    const QuantityVector asked = quantitiesOf(head.target), got = quantitiesOf(head.achieved);
    for (std::size_t i = 0; i < kCharacterQuantities; ++i)
        EXPECT_NEAR(got[i], asked[i], tolerance(i)) << what << ": " << sliderRanges()[i].quantity;
}

void writePng(const fs::path& file, const cv::Mat& image) {
    std::ofstream(file, std::ios::binary) << encodeImage(image, ".png");
}

glm::dvec3 featureOf(const Mesh& mesh, int k) { return mesh.positions[makeHuman().frontFeatures.at(landmarkName(k))]; }

}  // namespace

// Proportions a MakeHuman head really has: the base head with known control weights, measured.
CharacterProportions proportionsAtWeights(const std::vector<std::pair<std::string_view, double>>& set) {
    static const CharacterModel model = characterModelOf(makeHuman());
    std::vector<double> w(characterControls().size(), 0.0);
    for (const auto& [name, weight] : set)
        for (std::size_t c = 0; c < w.size(); ++c)
            if (characterControls()[c].modifiers[0] == name) w[c] = weight;
    return measureCharacter(model, makeHuman(), w);
}

TEST(CharacterMakeHuman, AskedProportionsComeBackWhenMeasured) {
    REQUIRE_MAKEHUMAN_HEAD();
    // Ground truth: two heads MakeHuman's sliders do make (every part moved, one way and then the other), measured;
    // their proportions asked for, the character made, and measured again.
    const CharacterProportions up = proportionsAtWeights({{"head/head-scale-vert-more", 0.3},
                                                          {"chin/chin-height-max", 0.4},
                                                          {"eyes/r-eye-move-out", 0.5},
                                                          {"eyes/l-eye-move-out", 0.3},
                                                          {"eyes/r-eye-size-big", 0.6},
                                                          {"ears/r-ear-trans-vert-up", 0.4},
                                                          {"ears/r-ear-height-max", 0.5},
                                                          {"eyebrows/eyebrows-trans-vert-more", 0.6},
                                                          {"nose/nose-trans-vert-down", 0.5},
                                                          {"mouth/mouth-trans-down", 0.5},
                                                          {"eyes/r-eye-corner1-up", 0.5},
                                                          {"eyebrows/eyebrows-angle-down", 0.3}});
    const CharacterProportions down = proportionsAtWeights({{"head/head-scale-horiz-more", 0.3},
                                                            {"chin/chin-height-min", 0.5},
                                                            {"eyes/r-eye-move-in", 0.6},
                                                            {"eyes/l-eye-move-in", 0.6},
                                                            {"eyes/r-eye-size-small", 0.5},
                                                            {"ears/r-ear-trans-vert-down", 0.2},
                                                            {"ears/r-ear-height-min", 0.5},
                                                            {"eyebrows/eyebrows-trans-vert-less", 0.5},
                                                            {"nose/nose-trans-vert-up", 0.5},
                                                            {"mouth/mouth-trans-up", 0.6},
                                                            {"eyes/r-eye-corner1-down", 0.4},
                                                            {"eyebrows/eyebrows-angle-up", 0.5}});
    printAndExpectReached("up", makeCharacterHead(makeHuman(), up, quick()));
    printAndExpectReached("down", makeCharacterHead(makeHuman(), down, quick()));
}

TEST(CharacterMakeHuman, SlidersAreTheBasisModifiersWithinTheirRanges) {
    REQUIRE_MAKEHUMAN_HEAD();
    CharacterProportions target = baseProportions();
    target.r[2] += 0.01;  // bigger eyes
    target.r[6] += 0.008;  // the nose tip further below the eye line: a lower nose
    const CharacterHead head = makeCharacterHead(makeHuman(), target, quick());
    const ModifierBasis& basis = *makeHuman().modifiers;
    std::size_t expected = 0;
    for (const CharacterControl& c : characterControls()) expected += c.modifiers.size();
    ASSERT_EQ(head.modifiers.size(), expected);
    std::set<std::string> names;
    for (const auto& [name, weight] : head.modifiers) {
        EXPECT_LT(basis.find(name), basis.modifiers.size()) << name;
        EXPECT_GE(weight, 0.0) << name;
        EXPECT_LE(weight, 1.0) << name;
        names.insert(name);
    }
    EXPECT_EQ(names.size(), expected);
    // The mesh is the basis applied with those weights.
    std::vector<double> w(basis.modifiers.size(), 0.0);
    for (const auto& [name, weight] : head.modifiers) w[basis.find(name)] = weight;
    const std::vector<glm::dvec3> rebuilt = basis.apply(makeHuman().mesh.positions, w);
    for (std::size_t v = 0; v < rebuilt.size(); ++v) ASSERT_NEAR(glm::distance(rebuilt[v], head.mesh.positions[v]), 0.0, 1e-9);
    // Bigger eyes and a lower nose were asked for: the big-eye and nose-down ends carry weight, their opposites none.
    const auto weightOf = [&](const std::string& n) {
        for (const auto& [name, weight] : head.modifiers)
            if (name == n) return weight;
        return -1.0;
    };
    EXPECT_GT(weightOf("eyes/r-eye-size-big"), 0.05);
    EXPECT_EQ(weightOf("eyes/r-eye-size-small"), 0.0);
    EXPECT_GT(weightOf("nose/nose-trans-vert-down"), 0.05);
    EXPECT_EQ(weightOf("nose/nose-trans-vert-up"), 0.0);
    // MakeHuman's two-sided form: one slider per pair of ends.
    const auto mh = makeHumanSliders(head.modifiers);
    bool sawNose = false;
    for (const auto& [name, value] : mh)
        if (name == "nose/nose-trans-vert-down|up") {
            sawNose = true;
            EXPECT_DOUBLE_EQ(value, -weightOf("nose/nose-trans-vert-down"));
        }
    EXPECT_TRUE(sawNose);
}

TEST(CharacterMakeHuman, ABiggerEyeRatioGivesBiggerEyes) {
    REQUIRE_MAKEHUMAN_HEAD();
    CharacterProportions small = baseProportions(), big = baseProportions();
    small.r[2] = 0.85 * baseProportions().r[2];
    big.r[2] = 1.2 * baseProportions().r[2];
    const CharacterHead a = makeCharacterHead(makeHuman(), small, quick());
    const CharacterHead b = makeCharacterHead(makeHuman(), big, quick());
    const auto eyeWidth = [](const Mesh& m) {
        return 0.5 * (glm::distance(glm::dvec2(featureOf(m, 36)), glm::dvec2(featureOf(m, 39))) +
                      glm::distance(glm::dvec2(featureOf(m, 42)), glm::dvec2(featureOf(m, 45))));
    };
    // The face width barely changes, so the eyes' width grows by about 1.2 / 0.85.
    EXPECT_NEAR(eyeWidth(b.mesh) / eyeWidth(a.mesh), 1.2 / 0.85, 0.06);
    EXPECT_NEAR(b.achieved.r[2] / a.achieved.r[2], 1.2 / 0.85, 0.05);
}

TEST(CharacterMakeHuman, TheBaseHeadsOwnProportionsLeaveItAsItIs) {
    REQUIRE_MAKEHUMAN_HEAD();
    const CharacterHead same = makeCharacterHead(makeHuman(), baseProportions(), quick());
    double worst = 0.0;
    for (const auto& [name, weight] : same.modifiers) worst = std::max(worst, weight);
    EXPECT_LT(worst, 0.02);
    EXPECT_TRUE(same.warnings.empty());
}

TEST(CharacterMakeHuman, ExaggerationPushesAwayFromTheAverage) {
    REQUIRE_MAKEHUMAN_HEAD();
    // A face MakeHuman makes at weights up to 0.35, so that twice as far is within the sliders' reach.
    const CharacterProportions wanted = proportionsAtWeights({{"chin/chin-height-max", 0.3},
                                                              {"eyes/r-eye-size-big", 0.35},
                                                              {"nose/nose-trans-vert-up", 0.3},
                                                              {"mouth/mouth-trans-down", 0.3},
                                                              {"eyebrows/eyebrows-angle-down", 0.15}});
    CharacterSettings once = quick(), twice = quick();
    twice.exaggeration = 2.0;
    const CharacterHead a = makeCharacterHead(makeHuman(), wanted, once);
    const CharacterHead b = makeCharacterHead(makeHuman(), wanted, twice);
    const QuantityVector q0 = quantitiesOf(baseProportions()), qa = quantitiesOf(a.achieved), qb = quantitiesOf(b.achieved),
                         ask = quantitiesOf(wanted);
    printReached("exaggeration 2", b);
    for (const std::size_t i : {0u, 2u, 6u, 7u, 10u}) {
        // Twice as far from the base head as asked, measured (within the measuring tolerance of each).
        EXPECT_NEAR(qb[i] - q0[i], 2.0 * (ask[i] - q0[i]), 2.0 * tolerance(i)) << sliderRanges()[i].quantity;
        EXPECT_GT(std::abs(qb[i] - q0[i]), std::abs(qa[i] - q0[i]) + 0.5 * std::abs(ask[i] - q0[i]))
            << sliderRanges()[i].quantity;
    }
}

// Real photos: the character of a few FRMDB people, its proportions against what their photos measure, and the
// pictures (front, three-quarter, side) beside the photo-style avatar's for a person to look at.
class CharacterFrmdb : public ::testing::TestWithParam<int> {};

TEST_P(CharacterFrmdb, MadeFromThePhotosAndDrawn) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    REQUIRE_MAKEHUMAN_HEAD();
    char person[8];
    std::snprintf(person, sizeof person, "%03d", GetParam());
    const fs::path dir = test::sharedData() / "frmdb" / person;
    static const FitPipeline pipeline{FitSettings{}, makeHuman()};
    const FitPhotoFiles inputs{dir / "Img_33.jpg", dir / "Img_53.jpg", {}};
    const FitOutcome outcome = pipeline.fit(inputs);
    const CharacterOutputs character = makeCharacterOutputs(outcome, makeHuman());
    static MeshRenderer renderer;
    const fs::path out = test::scratchDir(std::string("character_frmdb_") + person);
    writeSessionFolder(outcome, {inputs, &character}, out / "session", renderer);
    renderer.upload(character.head.mesh, character.head.texture);
    const PreviewSet previews = renderPreviews(renderer, character.head.mesh, 512);
    writePng(out / "character_front.png", previews.front);
    writePng(out / "character_side.png", previews.side);
    writePng(out / "character_three_quarter.png", previews.threeQuarter);
    std::printf("%s: character in %s (%.2f s)\n", person, out.c_str(), character.makeSeconds);
    // A real face asks for more than MakeHuman's sliders give (r1 from hair over one side, the brows' and nose's
    // heights beyond their sliders' ends): the character comes as near as the sliders allow, which is at least
    // half the way from the base head in the slider-range-weighted misfit the solve minimises.
    printReached(person, character.head);
    const auto misfit = [&](const CharacterProportions& p) {
        const QuantityVector q = quantitiesOf(p), t = quantitiesOf(character.head.target);
        double sum = 0.0;
        for (std::size_t i = 0; i < kCharacterQuantities; ++i) {
            const double d = (q[i] - t[i]) / (sliderRanges()[i].hi - sliderRanges()[i].lo);
            sum += d * d;
        }
        return sum;
    };
    const double before = misfit(character.head.base), after = misfit(character.head.achieved);
    std::printf("%s: misfit %.4f at the base head, %.4f on the character\n", person, before, after);
    EXPECT_LT(after, 0.5 * before);
    const nlohmann::json j = nlohmann::json::parse(character.json);
    ASSERT_TRUE(j["sliders"].is_object());
    EXPECT_EQ(j["sliders"].size(), character.head.modifiers.size());
    EXPECT_EQ(j["narita_sliders"].size(), 11u);
    EXPECT_EQ(j["ratios"].size(), 8u);
}

INSTANTIATE_TEST_SUITE_P(People, CharacterFrmdb, ::testing::Values(1, 3, 5));
