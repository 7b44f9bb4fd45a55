// The session store on a real filesystem: codes, keep (moved under the code, 0700/0600), discard (nothing left),
// retention with injected time (photos first, then the whole session), leftovers after a crash.
#include "booth/session_store.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <fstream>
#include <set>

using namespace avatarbooth;
namespace fs = std::filesystem;

namespace {

// A random source that plays back a list (then repeats its last value).
std::function<std::uint32_t()> sequence(std::vector<std::uint32_t> values) {
    auto state = std::make_shared<std::pair<std::vector<std::uint32_t>, std::size_t>>(std::move(values), 0);
    return [state] {
        auto& [v, i] = *state;
        const auto x = v[std::min(i, v.size() - 1)];
        ++i;
        return x;
    };
}

// The files a fit folder holds (as FitPipeline::write makes them), with their sizes in bytes.
const std::map<std::string, std::size_t> kFitFiles = {
    {"avatar.glb", 5000},        {"front.jpg", 3000},         {"side.jpg", 2900},
    {"front_overlay.jpg", 3100}, {"side_overlay.jpg", 2800},  {"landmarks.json", 400},
    {"preview_front.png", 900},  {"preview_side.png", 800},   {"preview_three_quarter.png", 850},
    {"fit.json", 600}};
constexpr std::size_t kPhotoBytes = 3000 + 2900 + 3100 + 2800;

// Writes a fit folder at `dir` the way the pipeline does (staged, then renamed into place).
void writeFit(const fs::path& dir) {
    StagedDirectory staged(dir, "fit.json");
    for (const auto& [name, size] : kFitFiles) writeFileAtomically(staged.staging() / name, std::string(size, 'x'));
    staged.commit();
}

unsigned permissionsOf(const fs::path& p) {
    struct stat st {};
    EXPECT_EQ(::stat(p.c_str(), &st), 0) << p;
    return st.st_mode & 07777;
}

std::set<std::string> filesIn(const fs::path& dir) {
    std::set<std::string> out;
    for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
    return out;
}

WallTime day(int d, int hours = 0, int seconds = 0) {
    return WallTime(std::chrono::hours(24 * (19000 + d) + hours) + std::chrono::seconds(seconds));
}

SessionStoreSettings settingsIn(const fs::path& dir) {
    SessionStoreSettings s;
    s.directory = dir / "sessions";
    return s;
}

}  // namespace

TEST(ShortCode, AlphabetHasNoLookAlikes) {
    EXPECT_EQ(kCodeAlphabet.size(), 32u);
    for (char c : std::string("0O1I")) EXPECT_EQ(kCodeAlphabet.find(c), std::string_view::npos) << c;
    EXPECT_EQ(std::set<char>(kCodeAlphabet.begin(), kCodeAlphabet.end()).size(), 32u);
}

TEST(ShortCode, MadeFromTheRandomSource) {
    EXPECT_EQ(makeShortCode(sequence({0, 1, 2, 3, 4, 5}), 6), "234567");
    EXPECT_EQ(makeShortCode(sequence({8, 31, 32, 63, 64 + 9, 100}), 6), "AZ2ZB6");
    EXPECT_EQ(makeShortCode(sequence({7}), 4), "9999");
}

TEST(ShortCode, NormalizesWhatAnOperatorTypes) {
    EXPECT_EQ(normalizeCode("ab3k7z", 6), "AB3K7Z");
    EXPECT_EQ(normalizeCode(" AB3-K7Z\n", 6), "AB3K7Z");
    EXPECT_EQ(normalizeCode("AB0K7Z", 6), std::nullopt);  // 0 is never in a code
    EXPECT_EQ(normalizeCode("ABIK7Z", 6), std::nullopt);
    EXPECT_EQ(normalizeCode("AB3K7", 6), std::nullopt);
    EXPECT_EQ(normalizeCode("AB3K7ZZ", 6), std::nullopt);
    EXPECT_EQ(normalizeCode("", 6), std::nullopt);
}

TEST(SessionStore, PhotoFilesForRetention) {
    for (const char* name : {"front.jpg", "side.png", "background.png", "front_overlay.jpg", "side_overlay.jpg"})
        EXPECT_TRUE(isPhotoFile(name)) << name;
    for (const char* name : {"avatar.glb", "fit.json", "landmarks.json", "session.json", "preview_front.png",
                             "preview_three_quarter.png", "front", ".front.jpg.tmp-1234", "frontal.jpg"})
        EXPECT_FALSE(isPhotoFile(name)) << name;
}

TEST(SessionStore, KeepMovesTheFitUnderItsCodeReadableOnlyByTheBooth) {
    const fs::path dir = test::scratchDir("session_store_keep");
    SessionStore store(settingsIn(dir), sequence({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 8, 9, 10, 11, 12, 13}));
    const fs::path pending = store.pendingPath();
    EXPECT_EQ(pending.parent_path(), dir / "sessions" / ".pending");
    EXPECT_FALSE(fs::exists(pending));
    writeFit(pending);

    const std::string code = store.keep(pending, day(10));
    EXPECT_EQ(code, "ABCDEF");
    const fs::path kept = dir / "sessions" / code;
    EXPECT_FALSE(fs::exists(pending));
    std::set<std::string> expected{"session.json"};
    for (const auto& [name, size] : kFitFiles) expected.insert(name);
    EXPECT_EQ(filesIn(kept), expected);
    EXPECT_EQ(permissionsOf(dir / "sessions"), 0700u);
    EXPECT_EQ(permissionsOf(kept), 0700u);
    for (const auto& name : expected) EXPECT_EQ(permissionsOf(kept / name), 0600u) << name;

    std::ifstream in(kept / "session.json");
    const std::string info((std::istreambuf_iterator<char>(in)), {});
    EXPECT_NE(info.find("\"code\": \"ABCDEF\""), std::string::npos) << info;
    EXPECT_NE(info.find("\"kept_at\": " + std::to_string(24LL * 3600 * 19010)), std::string::npos) << info;

    const auto sessions = store.list();
    ASSERT_EQ(sessions.size(), 1u);
    EXPECT_EQ(sessions[0].code, "ABCDEF");
    EXPECT_EQ(sessions[0].keptAt, day(10));
    EXPECT_TRUE(sessions[0].hasPhotos);
    EXPECT_EQ(store.find("abc-def"), kept);
    EXPECT_EQ(store.find("ABCDEG"), std::nullopt);
    EXPECT_EQ(store.find("ABCDE0"), std::nullopt);
    EXPECT_GT(store.freeBytes(), 0u);
}

TEST(SessionStore, CodeInUseIsNotReused) {
    const fs::path dir = test::scratchDir("session_store_collision");
    // Pending names take 12 draws each; then codes take 6. The second keep draws ABCDEF again, then 234567.
    std::vector<std::uint32_t> draws(12, 0);
    for (std::uint32_t v : {8, 9, 10, 11, 12, 13}) draws.push_back(v);
    for (int i = 0; i < 12; ++i) draws.push_back(1);
    for (std::uint32_t v : {8, 9, 10, 11, 12, 13, 0, 1, 2, 3, 4, 5}) draws.push_back(v);
    SessionStore store(settingsIn(dir), sequence(draws));
    const fs::path a = store.pendingPath();
    writeFit(a);
    EXPECT_EQ(store.keep(a, day(1)), "ABCDEF");
    const fs::path b = store.pendingPath();
    writeFit(b);
    EXPECT_EQ(store.keep(b, day(1)), "234567");
    EXPECT_EQ(store.list().size(), 2u);
}

TEST(SessionStore, KeepRefusesIncompleteOrForeignFolders) {
    const fs::path dir = test::scratchDir("session_store_refuse");
    SessionStore store(settingsIn(dir));
    const fs::path pending = store.pendingPath();
    fs::create_directories(pending);
    try {
        store.keep(pending, day(1));
        FAIL() << "kept a folder without fit.json";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Output);
        EXPECT_NE(std::string(e.what()).find("no fit.json"), std::string::npos) << e.what();
    }
    const fs::path elsewhere = dir / "elsewhere";
    writeFit(elsewhere);
    EXPECT_THROW(store.keep(elsewhere, day(1)), BoothError);
    EXPECT_TRUE(fs::exists(elsewhere / "fit.json"));
    EXPECT_TRUE(store.list().empty());
}

TEST(SessionStore, DiscardLeavesNothingBehind) {
    const fs::path dir = test::scratchDir("session_store_discard");
    SessionStore store(settingsIn(dir));
    const fs::path pending = store.pendingPath();
    writeFit(pending);
    // A fit that was interrupted while writing leaves a partial staging folder beside it.
    {
        StagedDirectory partial(pending.parent_path() / (pending.filename().string()), "fit.json");
        writeFileAtomically(partial.staging() / "front.jpg", "x");
        store.discard(pending);
        EXPECT_TRUE(fs::is_empty(dir / "sessions" / ".pending"));
    }
    EXPECT_TRUE(fs::is_empty(dir / "sessions" / ".pending"));
    EXPECT_TRUE(store.list().empty());
}

TEST(SessionStore, DiscardNeverDeletesAKeptSession) {
    const fs::path dir = test::scratchDir("session_store_discard_kept");
    SessionStore store(settingsIn(dir));
    const fs::path pending = store.pendingPath();
    writeFit(pending);
    const std::string code = store.keep(pending, day(1));
    try {
        store.discard(dir / "sessions" / code);
        FAIL() << "discarded a kept session";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Internal);
    }
    EXPECT_THROW(store.discard(dir / "sessions" / ".pending" / ".." / code), BoothError);
    EXPECT_TRUE(fs::exists(dir / "sessions" / code / "fit.json"));
}

TEST(SessionStore, RetentionDeletesPhotosFirstThenTheSession) {
    const fs::path dir = test::scratchDir("session_store_retention");
    SessionStore store(settingsIn(dir));
    auto keepAt = [&](WallTime t) {
        const fs::path p = store.pendingPath();
        writeFit(p);
        return store.keep(p, t);
    };
    const WallTime now = day(100);
    const std::string old = keepAt(now - std::chrono::hours(24 * 30));  // exactly 30 days: deleted
    const std::string youngerThan30 = keepAt(now - std::chrono::hours(24 * 30) + std::chrono::seconds(1));
    const std::string day1 = keepAt(now - std::chrono::hours(24));      // exactly 24 h: photos deleted
    const std::string fresh = keepAt(now - std::chrono::hours(24) + std::chrono::seconds(1));

    const RetentionReport r = store.applyRetention(now);
    EXPECT_EQ(r.sessionsDeleted, 1);
    EXPECT_EQ(r.photosDeleted, 8);  // 4 photos in each of the two sessions between 24 h and 30 days
    std::size_t all = 0;
    for (const auto& [name, size] : kFitFiles) all += size;
    const std::size_t sessionJson = fs::file_size(dir / "sessions" / fresh / "session.json");
    EXPECT_EQ(r.bytesFreed, all + sessionJson + 2 * kPhotoBytes);

    EXPECT_FALSE(fs::exists(dir / "sessions" / old));
    const std::set<std::string> withoutPhotos{"avatar.glb",        "fit.json",         "landmarks.json",
                                              "preview_front.png", "preview_side.png", "preview_three_quarter.png",
                                              "session.json"};
    EXPECT_EQ(filesIn(dir / "sessions" / youngerThan30), withoutPhotos);
    EXPECT_EQ(filesIn(dir / "sessions" / day1), withoutPhotos);
    EXPECT_EQ(filesIn(dir / "sessions" / fresh).size(), kFitFiles.size() + 1);

    const auto sessions = store.list();
    ASSERT_EQ(sessions.size(), 3u);
    EXPECT_EQ(sessions[0].code, fresh);  // newest first
    EXPECT_TRUE(sessions[0].hasPhotos);
    EXPECT_FALSE(sessions[1].hasPhotos);
    EXPECT_EQ(sessions[2].code, youngerThan30);

    // Nothing more to do at the same time; one second later the next session falls due.
    const RetentionReport again = store.applyRetention(now);
    EXPECT_EQ(again.sessionsDeleted + again.photosDeleted, 0);
    const RetentionReport next = store.applyRetention(now + std::chrono::seconds(1));
    EXPECT_EQ(next.sessionsDeleted, 1);
    EXPECT_EQ(next.photosDeleted, 4);
    EXPECT_EQ(store.list().size(), 2u);
    EXPECT_TRUE(fs::is_empty(dir / "sessions" / ".pending"));
    for (const auto& e : fs::directory_iterator(dir / "sessions"))
        EXPECT_NE(e.path().filename().string().rfind(".trash-", 0), 0u) << e.path();
}

TEST(SessionStore, RetentionOfZeroKeepsForever) {
    const fs::path dir = test::scratchDir("session_store_keep_forever");
    SessionStoreSettings s = settingsIn(dir);
    s.photoRetention = std::chrono::seconds(0);
    s.sessionRetention = std::chrono::seconds(0);
    SessionStore store(s);
    const fs::path p = store.pendingPath();
    writeFit(p);
    const std::string code = store.keep(p, day(0));
    const RetentionReport r = store.applyRetention(day(5000));
    EXPECT_EQ(r.photosDeleted + r.sessionsDeleted, 0);
    EXPECT_EQ(filesIn(dir / "sessions" / code).size(), kFitFiles.size() + 1);
}

TEST(SessionStore, KeepAvatarsButDeletePhotos) {
    const fs::path dir = test::scratchDir("session_store_keep_avatars");
    SessionStoreSettings s = settingsIn(dir);
    s.sessionRetention = std::chrono::seconds(0);
    SessionStore store(s);
    const fs::path p = store.pendingPath();
    writeFit(p);
    const std::string code = store.keep(p, day(0));
    const RetentionReport r = store.applyRetention(day(5000));
    EXPECT_EQ(r.photosDeleted, 4);
    EXPECT_EQ(r.sessionsDeleted, 0);
    EXPECT_TRUE(fs::exists(dir / "sessions" / code / "avatar.glb"));
}

TEST(SessionStore, SessionWithoutItsInfoFileAgesByTheFolderTime) {
    const fs::path dir = test::scratchDir("session_store_mtime");
    SessionStore store(settingsIn(dir));
    const fs::path p = store.pendingPath();
    writeFit(p);
    const std::string code = store.keep(p, day(0));
    const fs::path kept = dir / "sessions" / code;
    fs::remove(kept / "session.json");
    const auto now = std::chrono::system_clock::now();
    fs::last_write_time(kept, std::chrono::file_clock::from_sys(now - std::chrono::hours(25)));
    EXPECT_EQ(store.applyRetention(now).photosDeleted, 4);
}

TEST(SessionStore, LeftoversOfACrashAreRemoved) {
    const fs::path dir = test::scratchDir("session_store_leftovers");
    SessionStore store(settingsIn(dir));
    const fs::path kept = store.pendingPath();
    writeFit(kept);
    const std::string code = store.keep(kept, day(1));
    writeFit(store.pendingPath());                                 // a fit never kept nor discarded
    fs::create_directories(dir / "sessions" / ".trash-ABCDEF-XYZ234");  // a delete cut short
    std::ofstream(dir / "sessions" / ".trash-ABCDEF-XYZ234" / "avatar.glb") << "x";
    EXPECT_EQ(store.removeLeftovers(), 2);
    EXPECT_EQ(filesIn(dir / "sessions"), (std::set<std::string>{".pending", code}));
    EXPECT_TRUE(fs::is_empty(dir / "sessions" / ".pending"));
    EXPECT_EQ(store.removeLeftovers(), 0);
}

TEST(SessionStore, BadCodeLengthIsAConfigError) {
    SessionStoreSettings s;
    s.codeLength = 2;
    try {
        SessionStore store(s);
        FAIL();
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_EQ(e.where(), "sessions.code_length");
    }
}
