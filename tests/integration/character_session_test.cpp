// The character files as a fit writes them: character.glb valid under the Khronos validator and measuring, read
// back, what it was made to; character.json and character.glb in the session folder of a fitted synthetic
// visitor, written before fit.json, with the ear hole from the side photo and ratios close to what the visitor's
// true landmarks give.
#include "reveal/character/character_head.h"
#include "reveal/character/character_outputs.h"
#include "fit/export/glb.h"
#include "booth/session_folder.h"
#include "fit/fit_pipeline.h"
#include "sim/synthetic_visitor.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>

using namespace avatarbooth;
namespace fs = std::filesystem;

namespace {

MeshRenderer& renderer() {
    static MeshRenderer r;
    return r;
}

// Runs the Khronos validator on a glb; returns its one-line report, and whether it exited 0.
std::pair<bool, std::string> validate(const fs::path& glb) {
    const fs::path validator = fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "tests" / "gltf";
    if (!fs::exists(validator / "node_modules" / "gltf-validator")) return {false, "the glTF validator is missing: run tests/setup.sh"};
    const std::string cmd = "node '" + (validator / "validate.mjs").string() + "' '" + glb.string() + "' 2>&1";
    FILE* pipe = popen(cmd.c_str(), "r");
    std::string report;
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), buf.size(), pipe)) report += buf.data();
    return {pclose(pipe) == 0 && report.find("\"errors\":0") != std::string::npos, report};
}

nlohmann::json readJson(const fs::path& p) {
    std::ifstream in(p);
    return nlohmann::json::parse(in);
}

}  // namespace

TEST(CharacterSession, CharacterGlbIsValidAndKeepsItsProportions) {
    // The MakeHuman head, whose modifiers make the character (the built-in one has none).
    if (findMakeHumanBaseHead().empty()) GTEST_SKIP() << "the MakeHuman base head was not built";
    const BaseHead& base = *productBaseHead();
    CharacterProportions target = measureHead(base.mesh, base, base.earHoleCentre).proportions;
    target.r[2] += 0.02;
    target.r[7] += 0.02;
    target.eyeTiltDeg += 3.0;
    const CharacterHead head = makeCharacterHead(base, target);
    const fs::path dir = test::scratchDir("character_glb");
    writeGlb(dir / "character.glb", head.mesh, head.texture, "character");
    const auto [ok, report] = validate(dir / "character.glb");
    EXPECT_TRUE(ok) << report;

    // Read back (metres in the file, millimetres here) it measures what it was made to.
    const Mesh back = readGlbMesh(dir / "character.glb");
    ASSERT_EQ(back.positions.size(), head.mesh.positions.size());
    const CharacterProportions measured = measureHead(back, base, head.earHole).proportions;
    for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(measured.r[i], head.achieved.r[i], 0.002) << "r" << i;
    EXPECT_NEAR(measured.r[2], target.r[2], 0.005);
    EXPECT_NEAR(measured.eyeTiltDeg, target.eyeTiltDeg, 1.0);
    EXPECT_FALSE(readGlbTexture(dir / "character.glb").empty());
}

TEST(CharacterSession, AFitWritesTheCharacterFilesBeforeFitJson) {
    const BaseHead& base = builtinBaseHead();
    SyntheticVisitorOptions o;
    o.seed = 3;
    const SyntheticVisitor v = makeSyntheticVisitor(base, renderer(), o);
    const fs::path dir = test::scratchDir("character_session");
    writeSyntheticVisitorFolder(v, dir / "visitor");
    FitPipeline pipeline(FitSettings{});
    const FitPhotoFiles inputs{dir / "visitor" / "front.jpg", dir / "visitor" / "side.jpg", dir / "visitor" / "background.png"};
    const FitOutcome outcome = pipeline.fit(inputs);
    const CharacterOutputs character = makeCharacterOutputs(outcome, base);
    const std::vector<fs::path> written = writeSessionFolder(outcome, {inputs, &character}, dir / "session", renderer());

    ASSERT_FALSE(written.empty());
    EXPECT_EQ(written.back().filename(), "fit.json");
    const auto has = [&](const char* name) {
        return std::find(written.begin(), written.end(), dir / "session" / name) != written.end();
    };
    EXPECT_TRUE(has("character.json"));
    EXPECT_TRUE(has("character.glb"));
    const auto [ok, report] = validate(dir / "session" / "character.glb");
    EXPECT_TRUE(ok) << report;

    const nlohmann::json j = readJson(dir / "session" / "character.json");
    EXPECT_EQ(j["point_sources"]["ear_hole"], "side photo");
    // The built-in head has no modifiers: no model sliders, and the warning says why.
    EXPECT_TRUE(j["sliders"].is_object());
    EXPECT_TRUE(j["sliders"].empty());
    ASSERT_EQ(j["narita_sliders"].size(), 11u);
    for (const auto& [key, s] : j["narita_sliders"].items()) {
        EXPECT_GE(s["value"].get<double>(), 0.0) << key;
        EXPECT_LE(s["value"].get<double>(), 1.0) << key;
    }
    // The same mapping on the visitor's true landmarks (and the fit's silhouette and ear hole) gives close ratios.
    // The differences are dlib's: on this painted face it puts the brows' inner ends about 10 mm low (r5 0.09
    // against 0.15 for seed 3) and the chin about 4 mm high (r0 -0.04); the others agree within 0.02.
    NaritaMappingInput truth;
    for (int k = 0; k < 68; ++k) truth.landmarks[static_cast<std::size_t>(k)] = v.frontLandmarks.at(landmarkName(k));
    truth.mask = outcome.frontMask;
    truth.earHole = earHoleInFrontPhoto(outcome.fit, outcome.sideLandmarks);
    const CharacterProportions expected = computeProportions(mapNaritaPoints(truth).points);
    for (std::size_t i = 0; i < 8; ++i) {
        const double measured = j["ratios"]["r" + std::to_string(i)].get<double>();
        std::printf("r%zu: from dlib %.4f, from the true landmarks %.4f\n", i, measured, expected.r[i]);
        EXPECT_NEAR(measured, expected.r[i], i == 0 || i == 5 ? 0.07 : 0.02) << "r" << i;
    }
    const nlohmann::json fitReport = readJson(dir / "session" / "fit.json");
    bool timed = false;
    for (const auto& stage : fitReport["stages"]) timed = timed || stage["stage"] == "character";
    EXPECT_TRUE(timed);
}
