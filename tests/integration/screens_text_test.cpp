// The strings file (every key in both languages, errors that name file, line and key), the fonts (Debian's files,
// clear errors) and the FreeType text renderer (pixels drawn, fallback to the Japanese font, glyph cache, wrapping).
#include "booth/screens/strings.h"
#include "booth/screens/text_renderer.h"

#include "common/error.h"
#include "test_paths.h"

#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <regex>
#include <set>

using namespace avatarbooth;
namespace fs = std::filesystem;

namespace {

// The "{name}" placeholders in a string.
std::set<std::string> placeholders(const std::string& s) {
    std::set<std::string> out;
    const std::regex re("\\{[a-z_]+\\}");
    for (auto it = std::sregex_iterator(s.begin(), s.end(), re); it != std::sregex_iterator(); ++it)
        out.insert(it->str());
    return out;
}

// The shipped file with one line replaced (or removed when `with` is empty), written to a scratch folder.
fs::path editedStrings(const std::string& name, const std::string& line, const std::string& with) {
    std::ifstream in(StringTable::defaultFile());
    std::string text((std::istreambuf_iterator<char>(in)), {});
    const auto at = text.find(line);
    EXPECT_NE(at, std::string::npos) << line;
    text.replace(at, line.size(), with);
    const fs::path file = test::scratchDir("strings_" + name) / "strings.toml";
    std::ofstream(file) << text;
    return file;
}

std::string loadError(const fs::path& file) {
    try {
        StringTable::load(file);
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        return e.what();
    }
    ADD_FAILURE() << "loaded " << file;
    return "";
}

int inkPixels(const cv::Mat& bgr) {
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    return cv::countNonZero(grey > 128);
}

TextRenderer& renderer(Language language) {
    static TextRenderer en(resolveFonts(), Language::English);
    static TextRenderer ja(resolveFonts(), Language::Japanese);
    return language == Language::Japanese ? ja : en;
}

}  // namespace

TEST(Strings, ShippedFileHasEveryKeyInBothLanguages) {
    const StringTable t = StringTable::load(StringTable::defaultFile());
    EXPECT_EQ(t.keys(Language::English), t.keys(Language::Japanese));
    for (std::string_view key : requiredStringKeys()) {
        for (Language l : {Language::English, Language::Japanese}) {
            ASSERT_TRUE(t.has(l, key)) << key << " " << languageCode(l);
            EXPECT_FALSE(t.get(l, key).empty()) << key << " " << languageCode(l);
        }
        // The same placeholders in both languages: a translation cannot lose the code or a number.
        EXPECT_EQ(placeholders(t.get(Language::English, key)), placeholders(t.get(Language::Japanese, key))) << key;
    }
    // The Japanese strings are Japanese (a copy of the English would pass every other check).
    EXPECT_EQ(t.get(Language::Japanese, "hint.step_back"), "少し下がってください");
    EXPECT_EQ(t.get(Language::English, "hint.step_back"), "Step back a little");
}

TEST(Strings, FormatFillsPlaceholders) {
    const StringTable t = StringTable::load(StringTable::defaultFile());
    EXPECT_EQ(t.format(Language::English, "operator.sessions", {{"count", "12"}}), "12 sessions stored");
    EXPECT_EQ(t.format(Language::Japanese, "operator.sessions", {{"count", "12"}}), "保存されたセッション：12件");
    EXPECT_EQ(t.format(Language::English, "operator.freed", {{"photos", "4"}, {"sessions", "1"}, {"freed", "2 MB"}}),
              "Deleted 4 photos and 1 sessions, freed 2 MB");
    EXPECT_THROW(t.get(Language::English, "no.such.key"), BoothError);
}

TEST(Strings, MissingKeyInOneLanguageIsNamed) {
    const fs::path file = editedStrings("missing_ja", "hint.turn_more = \"もう少し右を向いてください\"\n", "");
    const std::string e = loadError(file);
    EXPECT_NE(e.find(file.string()), std::string::npos) << e;
    EXPECT_NE(e.find("[ja]"), std::string::npos) << e;
    EXPECT_NE(e.find("hint.turn_more"), std::string::npos) << e;
}

TEST(Strings, KeyInOnlyOneLanguageIsNamed) {
    const fs::path file =
        editedStrings("extra_en", "title = \"Avatar Booth\"\n", "title = \"Avatar Booth\"\nextra.key = \"x\"\n");
    const std::string e = loadError(file);
    EXPECT_NE(e.find("[ja]"), std::string::npos) << e;
    EXPECT_NE(e.find("extra.key"), std::string::npos) << e;
}

// The line of the shipped strings file that holds `text` (1-based), so that the tests follow the file as it grows.
int lineOf(const std::string& text) {
    std::ifstream in(StringTable::defaultFile());
    int n = 0;
    for (std::string line; std::getline(in, line);) {
        ++n;
        if (line.find(text) != std::string::npos) return n;
    }
    return -1;
}

TEST(Strings, NonStringValueNamesLineAndKey) {
    const fs::path file = editedStrings("number", "reveal.keep = \"Keep\"", "reveal.keep = 3");
    const std::string e = loadError(file);
    const int line = lineOf("reveal.keep = \"Keep\"");
    ASSERT_GT(line, 0);
    EXPECT_NE(e.find(file.string() + ":" + std::to_string(line) + ": reveal.keep"), std::string::npos) << e;
    EXPECT_NE(e.find("must be a string"), std::string::npos) << e;
}

TEST(Strings, SyntaxErrorNamesTheLine) {
    const fs::path file = editedStrings("syntax", "reveal.keep = \"Keep\"", "reveal.keep = \"Keep");
    const std::string e = loadError(file);
    EXPECT_NE(e.find(file.string() + ":" + std::to_string(lineOf("reveal.keep = \"Keep\""))), std::string::npos) << e;
}

TEST(Strings, MissingFileIsNamed) {
    const std::string e = loadError("/nonexistent/strings.toml");
    EXPECT_NE(e.find("/nonexistent/strings.toml"), std::string::npos) << e;
}

TEST(Fonts, ResolvedToDebianFiles) {
    const FontPaths f = resolveFonts();
    EXPECT_EQ(f.regular, "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf");
    EXPECT_EQ(f.bold, "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf");
    EXPECT_TRUE(fs::is_regular_file(f.japanese)) << f.japanese;
}

TEST(Fonts, MissingConfiguredFontIsAClearError) {
    FontPaths f;
    f.japanese = "/nonexistent/font.ttf";
    try {
        resolveFonts(f);
        FAIL();
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_EQ(e.where(), "/nonexistent/font.ttf");
        EXPECT_NE(std::string(e.what()).find("Japanese font file not found"), std::string::npos) << e.what();
    }
    // A file that is not a font: FreeType's refusal, naming the file.
    const fs::path bogus = test::scratchDir("fonts_bogus") / "bogus.ttf";
    std::ofstream(bogus) << "not a font";
    FontPaths g = resolveFonts();
    g.regular = bogus;
    try {
        TextRenderer t(g, Language::English);
        FAIL();
    } catch (const BoothError& e) {
        EXPECT_EQ(e.where(), bogus.string());
    }
}

TEST(TextRenderer, DrawsLatinAndJapaneseInBothLanguageSetups) {
    for (Language l : {Language::English, Language::Japanese}) {
        TextRenderer& t = renderer(l);
        for (const char* s : {"Hold still!", "そのまま動かないで！", "Code AB3K7Z / コード"}) {
            cv::Mat img(120, 900, CV_8UC3, cv::Scalar(0, 0, 0));
            t.draw(img, s, {10, 80}, 48, cv::Scalar(255, 255, 255));
            const auto m = t.measure(s, 48);
            EXPECT_GT(inkPixels(img), 500) << s << " " << languageCode(l);
            EXPECT_GT(m.width, 100) << s;
            EXPECT_LT(m.width, 890) << s;
            EXPECT_GT(m.ascent, 30);
            // Nothing drawn beyond the measured width (plus a pixel of anti-aliasing).
            EXPECT_EQ(cv::countNonZero(img.colRange(std::min(899, 10 + m.width + 2), 900).reshape(1) > 0), 0) << s;
        }
    }
}

TEST(TextRenderer, EachCharacterIsCoveredByAFont) {
    // The Japanese font falls in for characters DejaVu lacks: no "missing glyph" boxes. A box is drawn for
    // U+E000 (private use, in no font); real characters must not look like it.
    TextRenderer& t = renderer(Language::English);
    auto image = [&](const char* s) {
        cv::Mat img(80, 80, CV_8UC3, cv::Scalar(0, 0, 0));
        t.draw(img, s, {10, 60}, 48, cv::Scalar(255, 255, 255));
        return img;
    };
    const cv::Mat box = image("\xEE\x80\x80");
    for (const char* s : {"あ", "撮", "ー", "！"}) {
        cv::Mat diff;
        cv::absdiff(image(s), box, diff);
        EXPECT_GT(inkPixels(diff), 50) << s << " drew the missing-glyph box";
    }
}

TEST(TextRenderer, GlyphsAreCachedOnce) {
    TextRenderer t(resolveFonts(), Language::English);
    cv::Mat img(100, 600, CV_8UC3, cv::Scalar(0, 0, 0));
    t.draw(img, "abcabc", {0, 60}, 40, cv::Scalar(255, 255, 255));
    EXPECT_EQ(t.cachedGlyphs(), 3u);
    t.draw(img, "cab", {0, 60}, 40, cv::Scalar(255, 255, 255));
    EXPECT_EQ(t.cachedGlyphs(), 3u);
    t.draw(img, "cab", {0, 60}, 40, cv::Scalar(255, 255, 255), FontWeight::Bold);
    EXPECT_EQ(t.cachedGlyphs(), 6u);  // per weight
    t.measure("a", 41);
    EXPECT_EQ(t.cachedGlyphs(), 7u);  // and per size
}

TEST(TextRenderer, GlyphCacheStaysUnderItsBoundAndDrawsTheSameAfterEmptying) {
    TextRenderer t(resolveFonts(), Language::English);
    const std::string text = "ABCDEFGHJKLMNPQRSTUVWXYZ23456789";  // a session code's alphabet
    const auto drawAt = [&](TextRenderer& r, int px) {
        cv::Mat img(px * 2, px * 40, CV_8UC3, cv::Scalar(0, 0, 0));
        r.draw(img, text, {0, px * 3 / 2}, px, cv::Scalar(255, 255, 255), FontWeight::Bold);
        return img;
    };
    const cv::Mat first = drawAt(t, 120);
    const std::size_t oneSize = t.cachedGlyphBytes();
    EXPECT_GT(oneSize, 32u * 50 * 50);  // 32 glyphs of about 90x120 pixels
    // Every size from 100 to 220 pixels: tens of megabytes of bitmaps without a bound.
    std::size_t largest = 0, emptied = 0, before = t.cachedGlyphBytes();
    for (int px = 100; px <= 220; ++px) {
        drawAt(t, px);
        largest = std::max(largest, t.cachedGlyphBytes());
        if (t.cachedGlyphBytes() < before) ++emptied;
        before = t.cachedGlyphBytes();
    }
    EXPECT_GE(emptied, 3u);
    // Over the bound by at most one string's glyphs (the cache is emptied before a string, never during one).
    EXPECT_LE(largest, TextRenderer::kGlyphCacheBytes + 32u * 220 * 220);
    EXPECT_EQ(cv::norm(drawAt(t, 120), first, cv::NORM_INF), 0.0);  // refilled glyphs draw the same
    TextRenderer fresh(resolveFonts(), Language::English);
    EXPECT_EQ(cv::norm(drawAt(fresh, 120), first, cv::NORM_INF), 0.0);
}

TEST(TextRenderer, WrapsEnglishAtSpaces) {
    TextRenderer& t = renderer(Language::English);
    const int w = t.measure("aaa aaa", 40).width;
    EXPECT_EQ(t.wrap("aaa aaa aaa", 40, w), (std::vector<std::string>{"aaa aaa", "aaa"}));
    EXPECT_EQ(t.wrap("aaa aaa aaa", 40, w - 1), (std::vector<std::string>{"aaa", "aaa", "aaa"}));
    // Spaces at a break are dropped, however many.
    EXPECT_EQ(t.wrap("aaa   aaa", 40, t.measure("aaa", 40).width), (std::vector<std::string>{"aaa", "aaa"}));
    EXPECT_EQ(t.wrap("one\ntwo", 40, 1000), (std::vector<std::string>{"one", "two"}));
    // A word longer than the line is split between its letters.
    const auto lines = t.wrap("ABCDEFGHIJKLMNOP", 40, t.measure("ABCDEFG", 40).width);
    EXPECT_EQ(lines, (std::vector<std::string>{"ABCDEFG", "HIJKLMN", "OP"}));
}

TEST(TextRenderer, WrapsJapaneseBetweenCharactersButNotBeforeClosingPunctuation) {
    TextRenderer& t = renderer(Language::Japanese);
    const int w = t.measure("撮影できませんでした", 40).width;
    EXPECT_EQ(t.wrap("撮影できませんでした。もう一度撮りましょう。", 40, w),
              (std::vector<std::string>{"撮影できませんでし", "た。もう一度撮りま", "しょう。"}));  // not before 。 nor ょ
    for (const auto& line : t.wrap("撮影できませんでした。もう一度撮りましょう。", 40, w)) {
        EXPECT_LE(t.measure(line, 40).width, w) << line;
        EXPECT_NE(line.rfind("。", 0), 0u) << "a line starts with 。";
        EXPECT_NE(line.rfind("ょ", 0), 0u) << "a line starts with a small kana";
    }
}
