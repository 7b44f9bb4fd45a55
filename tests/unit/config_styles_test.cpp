// booth.toml's [character], [reveal] and [stage] tables: defaults equal the shipped reference, values land, and
// mistakes name the file, line and key (a broken stage map: its own file, line and column).
#include "test_paths.h"

#include "common/error.h"
#include "config/booth_config.h"

#include "config_error_of.h"

#include <gtest/gtest.h>

#include <fstream>

using namespace avatarbooth;

namespace {

using avatarbooth::test::errorOf;

}  // namespace

TEST(ConfigStyles, ShippedReferenceEqualsTheDefaults) {
    const BoothConfig shipped = loadBoothConfig(std::filesystem::path(AVATARBOOTH_TEST_SOURCE_DIR) / "app/assets/booth.toml");
    const BoothConfig defaults = parseBoothConfig("", "empty.toml");
    EXPECT_EQ(shipped.character.enabled, defaults.character.enabled);
    EXPECT_DOUBLE_EQ(shipped.character.settings.exaggeration, defaults.character.settings.exaggeration);
    EXPECT_EQ(shipped.character.settings.sliders, defaults.character.settings.sliders);
    EXPECT_EQ(shipped.character.settings.coloursFromPhoto, defaults.character.settings.coloursFromPhoto);
    EXPECT_EQ(shipped.character.settings.textureSize, defaults.character.settings.textureSize);
    EXPECT_EQ(shipped.reveal.styles, defaults.reveal.styles);
    EXPECT_EQ(shipped.reveal.toonColours, defaults.reveal.toonColours);
    EXPECT_EQ(shipped.reveal.toonStripFrames, defaults.reveal.toonStripFrames);
    EXPECT_EQ(shipped.stage.enabled, defaults.stage.enabled);
    EXPECT_EQ(shipped.stage.map, defaults.stage.map);
    EXPECT_DOUBLE_EQ(shipped.stage.sweepSeconds, defaults.stage.sweepSeconds);
    EXPECT_DOUBLE_EQ(shipped.stage.lowAngleDeg, defaults.stage.lowAngleDeg);
    // The defaults: every style, the stage on, all sliders.
    EXPECT_EQ(defaults.reveal.styles,
              (std::vector<AvatarStyle>{AvatarStyle::Photo, AvatarStyle::Character, AvatarStyle::Toon}));
    EXPECT_TRUE(defaults.stage.enabled);
    EXPECT_FALSE(defaults.character.settings.sliders.has_value());
}

TEST(ConfigStyles, ValuesLandInTheirSettings) {
    // A folder of its own per test: ctest runs tests in parallel, and scratchDir() empties the folder it returns.
    const std::filesystem::path dir = avatarbooth::test::scratchDir("config_styles_values");
    {
        std::ofstream(dir / "island.map") << "ggg\nbbb\n";
    }
    const BoothConfig c = parseBoothConfig(R"(
[character]
exaggeration = 1.4
sliders = ["face_aspect", "eye_size"]
colours = "fixed"
texture_size = 256
[reveal]
styles = ["toon", "photo"]
toon_colours = 4
toon_strip_frames = 36
[stage]
map = "island.map"
sweep_s = 8
low_angle_deg = 20
)", (dir / "booth.toml").string());
    EXPECT_DOUBLE_EQ(c.character.settings.exaggeration, 1.4);
    EXPECT_EQ(c.character.settings.sliders, (std::set<std::string>{"face_aspect", "eye_size"}));
    EXPECT_FALSE(c.character.settings.coloursFromPhoto);
    EXPECT_EQ(c.character.settings.textureSize, 256);
    EXPECT_EQ(c.reveal.styles, (std::vector<AvatarStyle>{AvatarStyle::Toon, AvatarStyle::Photo}));
    EXPECT_EQ(c.reveal.toonColours, 4);
    EXPECT_EQ(c.reveal.toonStripFrames, 36);
    EXPECT_EQ(c.stage.map, dir / "island.map");  // relative to the config file
    EXPECT_DOUBLE_EQ(c.stage.sweepSeconds, 8.0);
    EXPECT_DOUBLE_EQ(c.stage.lowAngleDeg, 20.0);

    // No sliders: the character keeps the base head's proportions (a set naming none, not "all").
    const BoothConfig none = parseBoothConfig("[character]\nsliders = []\n", "booth.toml");
    ASSERT_TRUE(none.character.settings.sliders.has_value());
    EXPECT_TRUE(none.character.settings.sliders->empty());
    // The character switched off leaves the default styles without it.
    const BoothConfig off = parseBoothConfig("[character]\nenabled = false\n", "booth.toml");
    EXPECT_FALSE(off.character.enabled);
    EXPECT_EQ(off.reveal.styles, (std::vector<AvatarStyle>{AvatarStyle::Photo, AvatarStyle::Toon}));
    EXPECT_FALSE(parseBoothConfig("[stage]\nenabled = false\nmap = \"/nonexistent.map\"\n", "b.toml").stage.enabled);
}

TEST(ConfigStyles, MistakesNameFileLineAndKey) {
    EXPECT_EQ(errorOf("[reveal]\nstyles = [\"photo\", \"anime\"]\n"),
              "booth.toml:2: reveal.styles: \"anime\" is not one of \"photo\", \"character\" or \"toon\"");
    EXPECT_EQ(errorOf("[reveal]\nstyles = [\"toon\", \"toon\"]\n"), "booth.toml:2: reveal.styles: \"toon\" is listed twice");
    EXPECT_EQ(errorOf("[reveal]\nstyles = []\n"),
              "booth.toml:2: reveal.styles: name at least 1 of \"photo\", \"character\" or \"toon\"");
    EXPECT_EQ(errorOf("[reveal]\nstyles = \"photo\"\n"),
              "booth.toml:2: reveal.styles: expected a list in brackets of \"photo\", \"character\" or \"toon\"");
    EXPECT_EQ(errorOf("[character]\nenabled = false\n[reveal]\nstyles = [\"character\"]\n"),
              "booth.toml:4: reveal.styles: \"character\" is listed but [character] enabled = false (remove it here, "
              "or enable it)");
    EXPECT_EQ(errorOf("[character]\nsliders = [\"nose_size\"]\n").rfind(
                  "booth.toml:2: character.sliders: \"nose_size\" is not one of \"face_aspect\", ", 0),
              0u);
    EXPECT_EQ(errorOf("[character]\nexaggeration = 5\n"),
              "booth.toml:2: character.exaggeration: must be between 0 and 3, got 5");
    EXPECT_EQ(errorOf("[character]\ncolours = \"sepia\"\n"),
              "booth.toml:2: character.colours: \"sepia\" is not one of \"photo\" or \"fixed\"");
    EXPECT_EQ(errorOf("[stage]\nlow_angle_deg = 60\n"), "booth.toml:2: stage.low_angle_deg: must be between 0 and 44, got 60");
    EXPECT_EQ(errorOf("[stage]\nmpa = \"x\"\n"),
              "booth.toml:2: stage.mpa: unknown key (see the reference booth.toml for the keys there are)");
    EXPECT_EQ(errorOf("[reveal]\ntoon_colours = 1\n"), "booth.toml:2: reveal.toon_colours: must be between 2 and 16, got 1");
}

TEST(ConfigStyles, ABrokenStageMapNamesItsOwnFileLineAndColumn) {
    const std::filesystem::path dir = avatarbooth::test::scratchDir("config_styles_broken_map");
    {
        std::ofstream(dir / "broken.map") << "# a comment\nggg\ngg?\n";
    }
    try {
        parseBoothConfig("[stage]\nmap = \"broken.map\"\n", (dir / "booth.toml").string());
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_EQ(e.where(), (dir / "broken.map").string() + ":3:3");
    }
    try {
        parseBoothConfig("[stage]\nmap = \"missing.map\"\n", (dir / "booth.toml").string());
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_NE(std::string(e.what()).find("missing.map"), std::string::npos) << e.what();
    }
}
