// The fuzzing seeds' adversarial files (tests/fuzz/corpus/) through the normal build: every one gives a clear
// error naming the file (or line) and what is wrong, or is read correctly — never a crash or a huge allocation.
// Truncated JPEG and PNG, a PNG/JPEG/BMP/PPM declaring a huge size, a zero-byte file, a folder named front.jpg,
// file names that are not UTF-8, broken TOML.
#include "common/error.h"
#include "common/image_io.h"
#include "config/booth_config.h"
#include "drivers/camera/sim_camera.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <map>
#include <optional>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

fs::path corpus(const std::string& target) { return fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / target; }

std::string readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The BoothError a call throws (fails the test when it throws something else or nothing).
template <typename F>
std::optional<BoothError> errorOf(F&& f) {
    try {
        f();
    } catch (const BoothError& e) {
        return e;
    }
    return std::nullopt;
}

fs::path copyAs(const fs::path& from, const fs::path& to) {
    fs::create_directories(to.parent_path());
    fs::copy_file(from, to, fs::copy_options::overwrite_existing);
    return to;
}

SimCamera openSim(const fs::path& folder) {
    SimCameraOptions o;
    o.folder = folder;
    o.previewWidth = 160;
    o.previewHeight = 120;
    return SimCamera(o, std::make_shared<SimCameraControls>(), std::make_shared<ManualCameraClock>());
}

}  // namespace

TEST(BadInputFiles, EveryPhotoSeedLoadsOrGivesAClearError) {
    const std::map<std::string, std::string> expected = {
        {"valid.jpg", ""},
        {"valid.png", ""},
        {"valid.bmp", ""},
        {"too_small.jpg", "too small"},
        {"truncated.jpg", "truncated"},
        {"truncated_header.jpg", "truncated"},
        {"truncated.png", "decoded"},
        {"huge_declared.png", "too large (30000x30000"},
        {"huge_declared_max.png", "too large"},
        {"huge_declared.jpg", "too large (65000x65000"},
        {"huge_declared.bmp", "too large (30000x30000"},
        {"huge_declared.ppm", "too large (30000x30000"},
        {"zero_size_declared.png", "empty image"},
        {"zero_byte", "empty"},
        {"not_an_image.txt", "not a JPEG or PNG"},
        {"jpeg_magic_only.jpg", "truncated"},
    };
    int seen = 0;
    for (const auto& entry : fs::directory_iterator(corpus("photo"))) {
        const std::string name = entry.path().filename().string();
        const auto want = expected.find(name);
        ASSERT_NE(want, expected.end()) << "a seed without an expectation here: " << name;
        ++seen;
        const auto error = errorOf([&] { (void)readPhoto(entry.path()); });
        if (want->second.empty()) {
            EXPECT_FALSE(error) << name << ": " << error->what();
            continue;
        }
        ASSERT_TRUE(error) << name << " was accepted";
        EXPECT_EQ(error->kind(), ErrorKind::BadInput) << name;
        EXPECT_NE(error->where().find(name), std::string::npos) << error->what();
        EXPECT_NE(std::string(error->what()).find(want->second), std::string::npos) << name << ": " << error->what();
    }
    EXPECT_EQ(seen, static_cast<int>(expected.size()));
}

TEST(BadInputFiles, AFolderNamedLikeAPhotoAndNamesThatAreNotUtf8) {
    const fs::path dir = test::scratchDir("bad_input_names");
    fs::create_directories(dir / "front.jpg");
    auto error = errorOf([&] { (void)readPhoto(dir / "front.jpg"); });
    ASSERT_TRUE(error);
    EXPECT_NE(std::string(error->what()).find("not a regular file"), std::string::npos) << error->what();

    // Linux file names are bytes: a name that is not UTF-8 is read like any other, and named in errors as is.
    const fs::path odd = copyAs(corpus("photo") / "valid.jpg", dir / "caf\xe9-\xff\xfe.jpg");
    EXPECT_EQ(readPhoto(odd).cols, 72);
    error = errorOf([&] { (void)readPhoto(dir / "missing-\xc3\x28.jpg"); });
    ASSERT_TRUE(error);
    EXPECT_NE(error->where().find("missing-\xc3\x28.jpg"), std::string::npos);
}

TEST(BadInputFiles, SessionFoldersForTheSimCamera) {
    const fs::path root = test::scratchDir("bad_input_sessions");
    const fs::path jpg = corpus("photo") / "valid.jpg";

    // A folder named front.jpg where the front photo should be.
    fs::path f = root / "front_is_a_folder";
    fs::create_directories(f / "front.jpg");
    copyAs(jpg, f / "side.jpg");
    auto error = errorOf([&] { (void)openSim(f); });
    ASSERT_TRUE(error);
    EXPECT_EQ(error->kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(error->what()).find("front.jpg"), std::string::npos) << error->what();
    EXPECT_NE(std::string(error->what()).find("not a regular file"), std::string::npos) << error->what();

    // Files whose names are not UTF-8 beside the photos are ignored.
    f = root / "non_utf8";
    copyAs(jpg, f / "front.jpg");
    copyAs(jpg, f / "side.jpg");
    copyAs(jpg, f / "\xff\xfe.jpg");
    EXPECT_EQ(openSim(f).sceneImage(SimScene::Front).cols, 72);

    // A background declaring a huge size is refused before it is decoded.
    f = root / "huge_background";
    copyAs(jpg, f / "front.jpg");
    copyAs(jpg, f / "side.jpg");
    copyAs(corpus("photo") / "huge_declared.png", f / "background.png");
    error = errorOf([&] { (void)openSim(f); });
    ASSERT_TRUE(error);
    EXPECT_NE(std::string(error->what()).find("too large"), std::string::npos) << error->what();

    // A truncated front photo and a zero-byte side photo.
    f = root / "truncated";
    copyAs(corpus("photo") / "truncated.jpg", f / "front.jpg");
    copyAs(jpg, f / "side.jpg");
    error = errorOf([&] { (void)openSim(f); });
    ASSERT_TRUE(error);
    EXPECT_NE(std::string(error->what()).find("truncated"), std::string::npos) << error->what();
    f = root / "zero_side";
    copyAs(jpg, f / "front.jpg");
    copyAs(corpus("photo") / "zero_byte", f / "side.jpg");
    error = errorOf([&] { (void)openSim(f); });
    ASSERT_TRUE(error);
    EXPECT_NE(std::string(error->what()).find("empty"), std::string::npos) << error->what();
}

TEST(BadInputFiles, EveryConfigSeedParsesOrNamesTheLine) {
    int seen = 0;
    for (const auto& entry : fs::directory_iterator(corpus("config"))) {
        const std::string name = entry.path().filename().string();
        ++seen;
        const auto error = errorOf([&] { (void)parseBoothConfig(readAll(entry.path()), name); });
        if (name == "empty.toml" || name == "reference_booth.toml") {
            EXPECT_FALSE(error) << name << ": " << error->what();
            continue;
        }
        ASSERT_TRUE(error) << name << " was accepted";
        EXPECT_EQ(error->kind(), ErrorKind::BadConfig) << name << ": " << error->what();
        // "name:LINE" (the line of the bad key, or where the TOML broke).
        EXPECT_EQ(error->where().rfind(name + ":", 0), 0u) << name << ": " << error->what();
    }
    EXPECT_GE(seen, 10);
}
