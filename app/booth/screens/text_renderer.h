// On-screen text: UTF-8 strings drawn into BGR images with FreeType, with font fallback (Latin and Japanese in one
// string), word/character wrapping and a glyph cache (screens redraw at 30 fps; a glyph is rasterised once).
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace avatarbooth {

enum class Language { English, Japanese };

// "en" / "ja" (the setting's values) and back.
Language parseLanguage(std::string_view code);
const char* languageCode(Language language);

// The font files. Empty fields are resolved to Debian's fonts at fixed paths (see resolveFonts).
struct FontPaths {
    std::filesystem::path regular;   // Latin text; default DejaVu Sans (fonts-dejavu-core)
    std::filesystem::path bold;      // Latin titles; default DejaVu Sans Bold (fonts-dejavu-core)
    std::filesystem::path japanese;  // Japanese text; default VL Gothic (fonts-vlgothic), else IPAGothic
                                     // (fonts-ipafont-gothic)
};

// Fills the empty fields with the first Debian font file that exists and checks that every file exists.
// Throws BoothError(BadConfig) naming the missing file and the Debian package that provides it.
FontPaths resolveFonts(const FontPaths& configured = {});

// Decodes UTF-8 into code points; invalid bytes become U+FFFD (so a bad string shows, rather than vanishes).
std::u32string decodeUtf8(std::string_view utf8);

enum class FontWeight { Regular, Bold };

// Not thread-safe (one renderer per drawing thread).
class TextRenderer {
public:
    // Opens the fonts. `language` decides which font comes first: Japanese text uses the Japanese font's Latin
    // glyphs too (one consistent look), English text falls back to it only for characters DejaVu lacks. The
    // Japanese font has no bold: it is emboldened synthetically. Throws BoothError(BadConfig) naming a font that
    // FreeType cannot open.
    TextRenderer(const FontPaths& fonts, Language language);
    ~TextRenderer();
    TextRenderer(const TextRenderer&) = delete;
    TextRenderer& operator=(const TextRenderer&) = delete;

    struct Metrics {
        int width = 0;      // advance width of the whole string, pixels
        int ascent = 0;     // above the baseline
        int descent = 0;    // below the baseline (positive)
        int lineHeight = 0; // baseline to baseline
    };
    Metrics measure(std::string_view utf8, int pixelSize, FontWeight weight = FontWeight::Regular);

    // Draws one line with its baseline's left end at `origin`. Colour is BGR; alpha 0..1 scales coverage.
    void draw(cv::Mat& bgr, std::string_view utf8, cv::Point origin, int pixelSize, cv::Scalar colour,
              FontWeight weight = FontWeight::Regular, double alpha = 1.0);

    // Splits text into lines no wider than maxWidth: at spaces, and between any two CJK characters (Japanese has
    // no spaces); a word longer than a line is split between characters. Explicit "\n" breaks a line.
    std::vector<std::string> wrap(std::string_view utf8, int pixelSize, int maxWidth,
                                  FontWeight weight = FontWeight::Regular);

    // Glyphs rasterised and kept (each once per font, size and weight), and the bytes their bitmaps take.
    std::size_t cachedGlyphs() const { return glyphs_.size(); }
    std::size_t cachedGlyphBytes() const { return glyphBytes_; }
    // The cache's bound. Text is drawn at sizes that depend on the text (a long line shrunk to fit its box), so
    // a booth that runs for weeks meets new sizes for ever; a cache that only grew would grow with it. When the
    // bitmaps pass this, the cache is emptied before the next string is laid out and refills with what the
    // screens use now: a few hundred kilobytes, so this is reached only by unusual text.
    static constexpr std::size_t kGlyphCacheBytes = std::size_t{4} << 20;

private:
    struct Face;
    struct Glyph {
        cv::Mat coverage;  // CV_8U
        int left = 0, top = 0;
        long advance26 = 0;  // 26.6 fixed point
    };
    struct Placed {
        const Glyph* glyph;
        long x26;  // pen position, 26.6
    };
    const Glyph& glyph(char32_t codepoint, int pixelSize, FontWeight weight);
    std::vector<Placed> layout(const std::u32string& text, int pixelSize, FontWeight weight, long* width26);
    void lineMetrics(int pixelSize, FontWeight weight, Metrics& m);
    // Empties the cache when it is over kGlyphCacheBytes. Called only where a call starts laying out a string:
    // a layout holds pointers into the cache until its string is drawn.
    void boundGlyphCache();

    void* library_ = nullptr;  // FT_Library
    std::vector<std::unique_ptr<Face>> faces_;
    std::vector<int> regularChain_, boldChain_;  // indices into faces_, in fallback order
    std::unordered_map<std::uint64_t, Glyph> glyphs_;
    std::size_t glyphBytes_ = 0;  // of the coverage bitmaps in glyphs_
};

}  // namespace avatarbooth
