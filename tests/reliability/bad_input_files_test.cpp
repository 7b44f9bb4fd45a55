// The fuzzing seeds' adversarial files (tests/fuzz/corpus/) through the normal build: every one gives a clear
// error naming the file (or line) and what is wrong, or is read correctly — never a crash or a huge allocation.
// Truncated JPEG and PNG, a PNG/JPEG/BMP/PPM declaring a huge size, a zero-byte file, a folder named front.jpg,
// file names that are not UTF-8, broken TOML, CSV manifests with missing columns, broken quotes, CRLF, a BOM.
#include "batch/batch_input.h"
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
    return SimCamera(o, std::make_shared<SimCameraControls>(), std::make_shared<ManualClock>(SteadyTime{}));
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
        {"pnm_no_pixels.ppm", "PNM data cannot be decoded"},  // found by fuzz_photo: "P692\n9"
        // Found by fuzz_photo in CI: a 16-bit PGM cut short, which stb_image read past its buffer.
        {"pnm16_truncated.pgm", "PNM data is truncated: its header declares 6x3000"},
        {"truncated.bmp", "BMP data is truncated"},  // the first half of valid.bmp (stb_image filled it with black)
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

// The manifest seeds (a flags byte choosing the columns, as fuzz_manifest.cpp reads it, then the CSV).
TEST(BadInputFiles, EveryManifestSeedReadsOrNamesTheFileAndLine) {
    const fs::path dir = test::scratchDir("bad_input_manifest");
    std::map<std::string, std::vector<BatchItem>> read;
    std::map<std::string, BoothError> failed;
    for (const auto& entry : fs::directory_iterator(corpus("manifest"))) {
        const std::string name = entry.path().filename().string();
        const std::string bytes = readAll(entry.path());
        const unsigned flags = bytes.empty() ? 0u : static_cast<unsigned char>(bytes[0]);
        const fs::path csv = dir / name / "pairs.csv";
        fs::create_directories(csv.parent_path());
        std::ofstream(csv, std::ios::binary) << (bytes.empty() ? std::string() : bytes.substr(1));
        ManifestColumns columns;
        if (flags & 1) columns.id = "id";
        if (flags & 2) columns.background = "background";
        if (flags & 4) columns.side = {"left", "right"};
        try {
            read[name] = readCsvManifest(csv, columns);
        } catch (const BoothError& e) {
            EXPECT_EQ(e.kind(), ErrorKind::BadInput) << name << ": " << e.what();
            EXPECT_EQ(e.where().rfind(csv.string(), 0), 0u) << name << ": the error does not name the file: " << e.what();
            failed.emplace(name, e);
        }
    }
    ASSERT_GE(read.size() + failed.size(), 15u);
    // Refused as a whole, naming what is wrong (and the header's line for a missing column).
    ASSERT_TRUE(failed.count("missing_columns"));
    EXPECT_NE(std::string(failed.at("missing_columns").what()).find("no column 'side'"), std::string::npos);
    EXPECT_EQ(failed.at("missing_columns").where(), (dir / "missing_columns" / "pairs.csv").string() + ":1");
    ASSERT_TRUE(failed.count("missing_id_column"));
    EXPECT_NE(std::string(failed.at("missing_id_column").what()).find("no column 'id'"), std::string::npos);
    ASSERT_TRUE(failed.count("unterminated_quote"));
    EXPECT_EQ(failed.at("unterminated_quote").where(), (dir / "unterminated_quote" / "pairs.csv").string() + ":2");
    ASSERT_TRUE(failed.count("empty"));
    EXPECT_EQ(failed.size(), 4u) << "more seeds refused than expected";

    // CRLF, a BOM, quoted fields (a comma, "" and line ends inside quotes), blank lines.
    ASSERT_EQ(read["crlf"].size(), 2u);
    EXPECT_EQ(read["crlf"][1].id, "ben");
    EXPECT_EQ(read["crlf"][1].side.filename(), "s2.jpg");  // no '\r' left on the last field
    ASSERT_EQ(read["bom"].size(), 1u);
    EXPECT_EQ(read["bom"][0].id, "anna");
    ASSERT_EQ(read["bom_crlf_no_final_newline"].size(), 1u);
    EXPECT_EQ(read["bom_crlf_no_final_newline"][0].background.filename(), "b.png");
    ASSERT_EQ(read["quoted_fields"].size(), 2u);
    EXPECT_EQ(read["quoted_fields"][0].id, "an_na");
    EXPECT_EQ(read["quoted_fields"][0].front.filename(), "\"front\".jpg");
    EXPECT_EQ(read["quoted_fields"][0].side.filename(), "multi\nline\nside.jpg");
    EXPECT_EQ(read["quoted_fields"][1].id, "ben");
    EXPECT_EQ(read["blank_lines_and_lone_cr"].size(), 1u);
    // Broken rows are items with a problem naming the file and line, never fitted.
    const auto& rows = read["short_and_long_rows"];
    ASSERT_EQ(rows.size(), 4u);
    for (const auto& item : rows) {
        EXPECT_EQ(item.problemKind, "bad_row") << item.source;
        EXPECT_NE(item.problem.find("pairs.csv:"), std::string::npos) << item.problem;
    }
    // Two sides per row: one item per side column; an empty cell is that item's problem only.
    ASSERT_EQ(read["two_sides_frmdb"].size(), 4u);
    EXPECT_EQ(read["two_sides_frmdb"][0].id, "001-left");
    EXPECT_TRUE(read["two_sides_frmdb"][0].problem.empty());
    EXPECT_EQ(read["two_sides_frmdb"][2].problemKind, "bad_row");
    EXPECT_TRUE(read["two_sides_frmdb"][3].problem.empty());
    // Names that are not UTF-8, "..", a hidden name: ids stay plain folder names inside the output folder.
    for (const auto& item : read["non_utf8_names"]) {
        EXPECT_FALSE(item.id.empty());
        EXPECT_NE(item.id.front(), '.') << item.id;
        EXPECT_EQ(item.id.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_."),
                  std::string::npos)
            << item.id;
    }
    EXPECT_THROW(requireUniqueIds(read["duplicate_ids"]), BoothError);
}
