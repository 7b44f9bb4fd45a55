// FreeType text drawing with fallback fonts, a glyph cache and line wrapping for Latin and Japanese text.
#include "booth/screens/text_renderer.h"

#include "common/error.h"

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H

#include <algorithm>
#include <cmath>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

struct Candidate {
    const char* path;
    const char* package;
};

// Debian's font files (fixed paths: no fontconfig needed on the kiosk).
constexpr Candidate kRegular[] = {{"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "fonts-dejavu-core"}};
constexpr Candidate kBold[] = {{"/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf", "fonts-dejavu-core"}};
constexpr Candidate kJapanese[] = {
    {"/usr/share/fonts/truetype/vlgothic/VL-Gothic-Regular.ttf", "fonts-vlgothic"},
    {"/usr/share/fonts/opentype/ipafont-gothic/ipag.ttf", "fonts-ipafont-gothic"},
    {"/usr/share/fonts/truetype/fonts-japanese-gothic.ttf", "fonts-vlgothic or fonts-ipafont-gothic"}};

template <std::size_t N>
fs::path resolveOne(const fs::path& configured, const Candidate (&candidates)[N], const char* what) {
    std::error_code ec;
    if (!configured.empty()) {
        if (!fs::is_regular_file(configured, ec))
            throw BoothError(ErrorKind::BadConfig, configured.string(), std::string(what) + " font file not found");
        return configured;
    }
    for (const auto& c : candidates)
        if (fs::is_regular_file(c.path, ec)) return c.path;
    throw BoothError(ErrorKind::BadConfig, candidates[0].path,
                     std::string(what) + " font not found: install the Debian package " + candidates[0].package +
                         " (or set the font's path in the configuration)");
}

bool isCjk(char32_t c) {
    return (c >= 0x2E80 && c <= 0x9FFF) || (c >= 0xF900 && c <= 0xFAFF) || (c >= 0xFF00 && c <= 0xFFEF) ||
           (c >= 0xAC00 && c <= 0xD7AF);
}

// Japanese line-breaking rules (kinsoku shori), the common subset: these never start a line ...
bool noLineStart(char32_t c) {
    static const std::u32string chars = U"、。，．・：；？！ー）」』】〕〉》’”ぁぃぅぇぉっゃゅょゎァィゥェォッャュョヮ…‥々!?,.:;)]}";
    return chars.find(c) != std::u32string::npos;
}
// ... and these never end one.
bool noLineEnd(char32_t c) {
    static const std::u32string chars = U"（「『【〔〈《‘“([{";
    return chars.find(c) != std::u32string::npos;
}

std::string encodeUtf8(const std::u32string& s) {
    std::string out;
    for (char32_t c : s) {
        if (c < 0x80) {
            out.push_back(static_cast<char>(c));
        } else if (c < 0x800) {
            out.push_back(static_cast<char>(0xC0 | (c >> 6)));
            out.push_back(static_cast<char>(0x80 | (c & 0x3F)));
        } else if (c < 0x10000) {
            out.push_back(static_cast<char>(0xE0 | (c >> 12)));
            out.push_back(static_cast<char>(0x80 | ((c >> 6) & 0x3F)));
            out.push_back(static_cast<char>(0x80 | (c & 0x3F)));
        } else {
            out.push_back(static_cast<char>(0xF0 | (c >> 18)));
            out.push_back(static_cast<char>(0x80 | ((c >> 12) & 0x3F)));
            out.push_back(static_cast<char>(0x80 | ((c >> 6) & 0x3F)));
            out.push_back(static_cast<char>(0x80 | (c & 0x3F)));
        }
    }
    return out;
}

std::string ftError(FT_Error e) {
    const char* s = FT_Error_String(e);
    return s ? s : "FreeType error " + std::to_string(e);
}

}  // namespace

Language parseLanguage(std::string_view code) {
    if (code == "en") return Language::English;
    if (code == "ja") return Language::Japanese;
    throw BoothError(ErrorKind::BadConfig, "language", "unknown language '" + std::string(code) + "' (en or ja)");
}

const char* languageCode(Language language) { return language == Language::Japanese ? "ja" : "en"; }

FontPaths resolveFonts(const FontPaths& configured) {
    FontPaths out;
    out.regular = resolveOne(configured.regular, kRegular, "regular");
    out.bold = resolveOne(configured.bold, kBold, "bold");
    out.japanese = resolveOne(configured.japanese, kJapanese, "Japanese");
    return out;
}

std::u32string decodeUtf8(std::string_view s) {
    std::u32string out;
    out.reserve(s.size());
    std::size_t i = 0;
    while (i < s.size()) {
        const auto b = static_cast<unsigned char>(s[i]);
        int len = 0;
        char32_t c = 0;
        if (b < 0x80) len = 1, c = b;
        else if ((b & 0xE0) == 0xC0) len = 2, c = b & 0x1F;
        else if ((b & 0xF0) == 0xE0) len = 3, c = b & 0x0F;
        else if ((b & 0xF8) == 0xF0) len = 4, c = b & 0x07;
        bool ok = len > 0 && i + static_cast<std::size_t>(len) <= s.size();
        for (int k = 1; ok && k < len; ++k) {
            const auto cb = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
            if ((cb & 0xC0) != 0x80) ok = false;
            else c = (c << 6) | (cb & 0x3F);
        }
        // Overlong forms, surrogates and values beyond U+10FFFF are invalid too.
        if (ok && ((len == 2 && c < 0x80) || (len == 3 && c < 0x800) || (len == 4 && c < 0x10000) ||
                   (c >= 0xD800 && c <= 0xDFFF) || c > 0x10FFFF))
            ok = false;
        if (!ok) {
            out.push_back(U'\uFFFD');
            ++i;
            continue;
        }
        out.push_back(c);
        i += static_cast<std::size_t>(len);
    }
    return out;
}

struct TextRenderer::Face {
    FT_Face face = nullptr;
    bool embolden = false;
    int pixelSize = 0;
    ~Face() {
        if (face) FT_Done_Face(face);
    }
    void setSize(int px) {
        if (px == pixelSize) return;
        FT_Set_Pixel_Sizes(face, 0, static_cast<FT_UInt>(px));
        pixelSize = px;
    }
};

TextRenderer::TextRenderer(const FontPaths& fonts, Language language) {
    FT_Library lib = nullptr;
    if (FT_Error e = FT_Init_FreeType(&lib))
        throw BoothError(ErrorKind::Internal, "", "cannot start FreeType: " + ftError(e));
    library_ = lib;
    auto open = [&](const fs::path& path, bool embolden) {
        auto f = std::make_unique<Face>();
        if (FT_Error e = FT_New_Face(lib, path.c_str(), 0, &f->face)) {
            f->face = nullptr;
            throw BoothError(ErrorKind::BadConfig, path.string(), "cannot open the font: " + ftError(e));
        }
        f->embolden = embolden;
        faces_.push_back(std::move(f));
        return static_cast<int>(faces_.size() - 1);
    };
    try {
        const int regular = open(fonts.regular, false);
        const int bold = open(fonts.bold, false);
        const int japanese = open(fonts.japanese, false);
        const int japaneseBold = open(fonts.japanese, true);
        if (language == Language::Japanese) {
            regularChain_ = {japanese, regular};
            boldChain_ = {japaneseBold, bold};
        } else {
            regularChain_ = {regular, japanese};
            boldChain_ = {bold, japaneseBold};
        }
    } catch (...) {
        faces_.clear();
        FT_Done_FreeType(lib);
        throw;
    }
}

TextRenderer::~TextRenderer() {
    glyphs_.clear();
    faces_.clear();
    FT_Done_FreeType(static_cast<FT_Library>(library_));
}

const TextRenderer::Glyph& TextRenderer::glyph(char32_t cp, int px, FontWeight weight) {
    const std::uint64_t key = (static_cast<std::uint64_t>(weight == FontWeight::Bold) << 63) |
                              (static_cast<std::uint64_t>(px & 0x7FFF) << 32) | static_cast<std::uint64_t>(cp);
    if (auto it = glyphs_.find(key); it != glyphs_.end()) return it->second;

    const auto& chain = weight == FontWeight::Bold ? boldChain_ : regularChain_;
    Face* face = faces_[static_cast<std::size_t>(chain.front())].get();
    FT_UInt index = 0;
    for (int i : chain) {
        const FT_UInt found = FT_Get_Char_Index(faces_[static_cast<std::size_t>(i)]->face, cp);
        if (found != 0) {
            face = faces_[static_cast<std::size_t>(i)].get();
            index = found;
            break;
        }
    }
    // index 0 is the font's "missing glyph" box: a character no font has still shows as something.
    face->setSize(px);
    Glyph g;
    FT_GlyphSlot slot = face->face->glyph;
    if (FT_Load_Glyph(face->face, index, FT_LOAD_DEFAULT | FT_LOAD_NO_BITMAP) == 0) {
        FT_Pos extra = 0;
        if (face->embolden && slot->format == FT_GLYPH_FORMAT_OUTLINE) {
            extra = std::max<FT_Pos>(64, px * 64 / 24);  // stroke 1/24 of the size: DejaVu Bold's weight
            FT_Outline_Embolden(&slot->outline, extra);
        }
        if (FT_Render_Glyph(slot, FT_RENDER_MODE_NORMAL) == 0) {
            const FT_Bitmap& bm = slot->bitmap;
            if (bm.width > 0 && bm.rows > 0) {
                g.coverage.create(static_cast<int>(bm.rows), static_cast<int>(bm.width), CV_8U);
                for (int r = 0; r < g.coverage.rows; ++r)
                    std::copy_n(bm.buffer + static_cast<std::ptrdiff_t>(r) * bm.pitch, bm.width, g.coverage.ptr(r));
            }
            g.left = slot->bitmap_left;
            g.top = slot->bitmap_top;
        }
        g.advance26 = slot->advance.x + extra;
    }
    glyphBytes_ += g.coverage.total();
    return glyphs_.emplace(key, std::move(g)).first->second;
}

void TextRenderer::boundGlyphCache() {
    if (glyphBytes_ <= kGlyphCacheBytes) return;
    glyphs_.clear();
    glyphBytes_ = 0;
}

std::vector<TextRenderer::Placed> TextRenderer::layout(const std::u32string& text, int px, FontWeight weight,
                                                       long* width26) {
    boundGlyphCache();
    std::vector<Placed> out;
    out.reserve(text.size());
    long pen = 0;
    for (char32_t c : text) {
        if (c == U'\n') continue;
        const Glyph& g = glyph(c, px, weight);
        out.push_back({&g, pen});
        pen += g.advance26;
    }
    if (width26) *width26 = pen;
    return out;
}

void TextRenderer::lineMetrics(int px, FontWeight weight, Metrics& m) {
    const auto& chain = weight == FontWeight::Bold ? boldChain_ : regularChain_;
    Face* f = faces_[static_cast<std::size_t>(chain.front())].get();
    f->setSize(px);
    const FT_Size_Metrics& sm = f->face->size->metrics;
    m.ascent = static_cast<int>((sm.ascender + 63) >> 6);
    m.descent = static_cast<int>((-sm.descender + 63) >> 6);
    m.lineHeight = static_cast<int>((sm.height + 63) >> 6);
}

TextRenderer::Metrics TextRenderer::measure(std::string_view utf8, int px, FontWeight weight) {
    Metrics m;
    lineMetrics(px, weight, m);
    long w26 = 0;
    layout(decodeUtf8(utf8), px, weight, &w26);
    m.width = static_cast<int>((w26 + 63) >> 6);
    return m;
}

void TextRenderer::draw(cv::Mat& bgr, std::string_view utf8, cv::Point origin, int px, cv::Scalar colour,
                        FontWeight weight, double alpha) {
    CV_Assert(bgr.type() == CV_8UC3);
    const int a255 = std::clamp(static_cast<int>(std::lround(alpha * 255.0)), 0, 255);
    if (a255 == 0) return;
    const int col[3] = {static_cast<int>(colour[0]), static_cast<int>(colour[1]), static_cast<int>(colour[2])};
    for (const Placed& p : layout(decodeUtf8(utf8), px, weight, nullptr)) {
        const cv::Mat& cov = p.glyph->coverage;
        if (cov.empty()) continue;
        const int x0 = origin.x + static_cast<int>((p.x26 + 32) >> 6) + p.glyph->left;
        const int y0 = origin.y - p.glyph->top;
        const int r0 = std::max(0, -y0), r1 = std::min(cov.rows, bgr.rows - y0);
        const int c0 = std::max(0, -x0), c1 = std::min(cov.cols, bgr.cols - x0);
        for (int r = r0; r < r1; ++r) {
            const uchar* s = cov.ptr(r);
            uchar* d = bgr.ptr(y0 + r) + 3 * (x0 + c0);
            for (int c = c0; c < c1; ++c, d += 3) {
                const int a = s[c] * a255;  // 0..65025
                if (a == 0) continue;
                for (int k = 0; k < 3; ++k) d[k] = static_cast<uchar>(d[k] + ((col[k] - d[k]) * a + 32512) / 65025);
            }
        }
    }
}

std::vector<std::string> TextRenderer::wrap(std::string_view utf8, int px, int maxWidth, FontWeight weight) {
    boundGlyphCache();
    std::vector<std::string> lines;
    const long max26 = static_cast<long>(maxWidth) * 64;
    const std::u32string all = decodeUtf8(utf8);
    std::size_t paraStart = 0;
    while (paraStart <= all.size()) {
        std::size_t paraEnd = all.find(U'\n', paraStart);
        if (paraEnd == std::u32string::npos) paraEnd = all.size();
        const std::u32string para = all.substr(paraStart, paraEnd - paraStart);
        std::size_t start = 0;
        while (start < para.size()) {
            long width = 0;
            std::size_t lastBreak = std::u32string::npos;  // a line may end before this index
            std::size_t i = start;
            for (; i < para.size(); ++i) {
                const char32_t c = para[i];
                if (i > start) {
                    const char32_t prev = para[i - 1];
                    const bool cjkPair = (isCjk(prev) || isCjk(c)) && !noLineStart(c) && !noLineEnd(prev);
                    if (c == U' ' || prev == U' ' || cjkPair) lastBreak = i;
                }
                const long adv = glyph(c, px, weight).advance26;
                if (width + adv > max26 && i > start && c != U' ') break;
                width += adv;
            }
            std::size_t end = i;
            if (i < para.size() && lastBreak != std::u32string::npos && lastBreak > start) end = lastBreak;
            std::size_t trimmed = end;
            while (trimmed > start && para[trimmed - 1] == U' ') --trimmed;
            lines.push_back(encodeUtf8(para.substr(start, trimmed - start)));
            start = end;
            while (start < para.size() && para[start] == U' ') ++start;
        }
        if (para.empty()) lines.emplace_back();
        paraStart = paraEnd + 1;
    }
    return lines;
}

}  // namespace avatarbooth
