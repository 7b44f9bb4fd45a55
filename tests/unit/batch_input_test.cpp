// Batch inputs: CSV manifests (columns, quoting, broken rows, missing columns), folders of session folders, and the
// shard split (every session in exactly one shard, the same shard on every run and whatever the other rows).
#include "batch/batch_input.h"
#include "common/error.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <set>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

fs::path writeFile(const fs::path& path, const std::string& text) {
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

std::string manifestErrorOf(const fs::path& csv, const ManifestColumns& columns) {
    try {
        readCsvManifest(csv, columns);
    } catch (const BoothError& e) {
        return e.what();
    }
    return "(no error)";
}

}  // namespace

TEST(BatchManifest, ReadsTheNamedColumnsRelativeToTheManifest) {
    const fs::path dir = test::scratchDir("unit_batch_manifest");
    const fs::path csv = writeFile(dir / "m.csv",
                                   "person_id,front,profile_l,profile_r\n001,001/f.jpg,001/l.jpg,/abs/r.jpg\n"
                                   "002,002/f.jpg,002/l.jpg,002/r.jpg\n");
    ManifestColumns c;
    c.front = "front";
    c.side = {"profile_l"};
    const auto items = readCsvManifest(csv, c);
    ASSERT_EQ(items.size(), 2u);
    EXPECT_EQ(items[0].id, "001");  // the first column names the session by default
    EXPECT_EQ(items[0].front, dir / "001/f.jpg");
    EXPECT_EQ(items[0].side, dir / "001/l.jpg");
    EXPECT_TRUE(items[0].background.empty());
    EXPECT_TRUE(items[0].problem.empty());
    EXPECT_EQ(items[1].source, "m.csv:3");

    c.side = {"profile_l", "profile_r"};  // two sides: one session per row and side column
    const auto both = readCsvManifest(csv, c);
    ASSERT_EQ(both.size(), 4u);
    EXPECT_EQ(both[0].id, "001-profile_l");
    EXPECT_EQ(both[1].id, "001-profile_r");
    EXPECT_EQ(both[1].side, fs::path("/abs/r.jpg"));
    EXPECT_NO_THROW(requireUniqueIds(both));
}

TEST(BatchManifest, MissingColumnIsAnErrorNamingTheColumnAndTheFile) {
    const fs::path dir = test::scratchDir("unit_batch_manifest_columns");
    const fs::path csv = writeFile(dir / "pairs.csv", "person_id,front,profile\n001,a.jpg,b.jpg\n");
    ManifestColumns c;  // defaults: front, side
    const std::string e = manifestErrorOf(csv, c);
    EXPECT_NE(e.find("'side'"), std::string::npos) << e;
    EXPECT_NE(e.find("--side-column"), std::string::npos) << e;
    EXPECT_NE(e.find(csv.string()), std::string::npos) << e;
    EXPECT_NE(e.find("person_id, front, profile"), std::string::npos) << e;  // the columns there are
    c.side = {"profile"};
    c.front = "frontal";
    const std::string f = manifestErrorOf(csv, c);
    EXPECT_NE(f.find("'frontal'"), std::string::npos) << f;
    c.front = "front";
    c.id = "who";
    EXPECT_NE(manifestErrorOf(csv, c).find("'who'"), std::string::npos);
}

TEST(BatchManifest, QuotesCrlfBomAndBrokenRows) {
    const fs::path dir = test::scratchDir("unit_batch_manifest_rows");
    const fs::path csv = writeFile(dir / "q.csv",
                                   "\xEF\xBB\xBFid,front,side\r\n"
                                   "\"a,1\",\"dir with, comma/f.jpg\",\"say \"\"hi\"\".jpg\"\r\n"
                                   "\r\n"
                                   "b,b/f.jpg\r\n"          // too few fields
                                   "c,,c/s.jpg\r\n"         // empty front
                                   ",d/f.jpg,d/s.jpg\r\n"   // empty id
                                   "../e,e/f.jpg,e/s.jpg\r\n");
    const auto items = readCsvManifest(csv, ManifestColumns{});
    ASSERT_EQ(items.size(), 5u);
    EXPECT_EQ(items[0].id, "a_1");  // ids are made safe to name a folder
    EXPECT_EQ(items[0].front, dir / "dir with, comma/f.jpg");
    EXPECT_EQ(items[0].side, dir / "say \"hi\".jpg");
    EXPECT_TRUE(items[0].problem.empty()) << items[0].problem;
    EXPECT_EQ(items[1].problemKind, "bad_row");
    EXPECT_NE(items[1].problem.find("q.csv:4"), std::string::npos) << items[1].problem;
    EXPECT_NE(items[1].problem.find("2 fields"), std::string::npos) << items[1].problem;
    EXPECT_EQ(items[2].problemKind, "bad_row");
    EXPECT_NE(items[2].problem.find("'front' is empty"), std::string::npos) << items[2].problem;
    EXPECT_EQ(items[3].problemKind, "bad_row");
    EXPECT_EQ(items[3].id, "line6");
    EXPECT_EQ(items[4].id, "_._e");  // cannot climb out of the output folder
    EXPECT_TRUE(items[4].problem.empty());
}

TEST(BatchManifest, FileLevelErrors) {
    const fs::path dir = test::scratchDir("unit_batch_manifest_files");
    EXPECT_NE(manifestErrorOf(dir / "none.csv", {}).find("not found"), std::string::npos);
    EXPECT_NE(manifestErrorOf(writeFile(dir / "empty.csv", ""), {}).find("empty"), std::string::npos);
    EXPECT_NE(manifestErrorOf(writeFile(dir / "open.csv", "id,front,side\n1,\"a.jpg,b.jpg\n"), {}).find("open.csv:2"),
              std::string::npos);
    const fs::path dup = writeFile(dir / "dup.csv", "id,front,side\n1,a,b\n1,c,d\n");
    try {
        requireUniqueIds(readCsvManifest(dup, {}));
        ADD_FAILURE() << "duplicate ids accepted";
    } catch (const BoothError& e) {
        EXPECT_NE(std::string(e.what()).find("dup.csv:2"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("dup.csv:3"), std::string::npos) << e.what();
    }
}

TEST(BatchFolders, SessionFoldersInNameOrder) {
    const fs::path dir = test::scratchDir("unit_batch_folders");
    writeFile(dir / "b" / "front.png", "x");
    writeFile(dir / "b" / "side.jpg", "x");
    writeFile(dir / "a" / "front.jpg", "x");
    writeFile(dir / "a" / "side.jpeg", "x");
    writeFile(dir / "a" / "background.jpg", "x");
    writeFile(dir / "c" / "front.jpg", "x");  // no side photo
    writeFile(dir / ".hidden" / "front.jpg", "x");
    writeFile(dir / "notes.txt", "x");
    const auto items = readBatchInput(dir, {});
    ASSERT_EQ(items.size(), 3u);
    EXPECT_EQ(items[0].id, "a");
    EXPECT_EQ(items[0].side, dir / "a" / "side.jpeg");
    EXPECT_EQ(items[0].background, dir / "a" / "background.jpg");
    EXPECT_EQ(items[1].front, dir / "b" / "front.png");
    EXPECT_TRUE(items[1].background.empty());
    EXPECT_EQ(items[2].problemKind, "missing_file");
    EXPECT_NE(items[2].problem.find("no side"), std::string::npos) << items[2].problem;
    EXPECT_THROW(readBatchInput(dir / "missing", {}), BoothError);
}

TEST(BatchShard, ParsesIOfN) {
    EXPECT_EQ(parseShard("2/4").index, 2);
    EXPECT_EQ(parseShard("2/4").count, 4);
    EXPECT_EQ(parseShard("1/1").count, 1);
    for (const char* bad : {"0/4", "5/4", "1/0", "a/b", "2", "2/4x", "/4", "-1/4", ""})
        EXPECT_THROW(parseShard(bad), BoothError) << bad;
}

TEST(BatchShard, EveryItemInExactlyOneShardAndStable) {
    std::vector<BatchItem> items;
    for (int k = 0; k < 1000; ++k) items.push_back(BatchItem{"person" + std::to_string(k), {}, {}, {}, "", "", ""});
    for (const int n : {1, 2, 3, 7}) {
        std::map<std::string, int> seen;
        std::size_t smallest = items.size(), largest = 0;
        for (int i = 1; i <= n; ++i) {
            const auto part = selectShard(items, {i, n});
            smallest = std::min(smallest, part.size());
            largest = std::max(largest, part.size());
            for (const auto& it : part) ++seen[it.id];
        }
        EXPECT_EQ(seen.size(), items.size()) << n;
        for (const auto& [id, count] : seen) EXPECT_EQ(count, 1) << id << " in " << count << " of " << n << " shards";
        // A hash split is only roughly even; with 1000 ids no shard should be far off.
        EXPECT_GT(static_cast<double>(smallest), 0.75 * 1000.0 / n) << n;
        EXPECT_LT(static_cast<double>(largest), 1.25 * 1000.0 / n) << n;
    }
    // The same on every run and machine: FNV-1a 64 of the id (reference values of the published algorithm).
    EXPECT_EQ(stableIdHash(""), 14695981039346656037ull);
    EXPECT_EQ(stableIdHash("a"), 0xaf63dc4c8601ec8cull);
    EXPECT_EQ(stableIdHash("foobar"), 0x85944171f73967e8ull);
    // A session's shard depends on its id alone: removing other rows does not move it.
    std::vector<BatchItem> fewer(items.begin() + 500, items.end());
    for (const auto& it : selectShard(fewer, {2, 3})) EXPECT_EQ(shardOf(it.id, 3), 2);
    EXPECT_EQ(selectShard(fewer, {2, 3}).size() + selectShard(fewer, {1, 3}).size() + selectShard(fewer, {3, 3}).size(),
              fewer.size());
}
