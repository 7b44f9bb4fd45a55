// The printed card's layout (see card.h). Drawn in millimetres: the PDF surface's points are scaled once.
#include "print/card.h"

#include "booth/screens/qr_code.h"
#include "common/error.h"
#include "common/image_io.h"

#include <cairo-pdf.h>
#include <cairo.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <memory>
#include <vector>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;

constexpr double kPointsPerMm = 72.0 / 25.4;
constexpr const char* kFont = "DejaVu Sans";  // fonts-dejavu-core, which the screens use too (through fontconfig)

cv::Mat readOptional(const fs::path& file) {
    std::error_code ec;
    if (!fs::exists(file, ec)) return {};
    return readPhoto(file);
}

struct Box {
    double x, y, w, h;  // millimetres from the card's top left
};

using Context = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

// `image` fitted into `box` (aspect kept, centred), resampled to the box's size at `dpi` so that the PDF holds
// the pixels the printer needs and no more.
void drawPicture(cairo_t* cr, const cv::Mat& image, const Box& box, int dpi) {
    const double scale = std::min(box.w / image.cols, box.h / image.rows);  // mm per source pixel
    const double wMm = image.cols * scale, hMm = image.rows * scale;
    const int wPx = std::max(1, static_cast<int>(wMm / 25.4 * dpi + 0.5));
    const int hPx = std::max(1, static_cast<int>(hMm / 25.4 * dpi + 0.5));
    cv::Mat sized, bgra;
    cv::resize(image, sized, {wPx, hPx}, 0, 0, wPx < image.cols ? cv::INTER_AREA : cv::INTER_CUBIC);
    cv::cvtColor(sized, bgra, cv::COLOR_BGR2BGRA);  // Cairo's ARGB32 is B, G, R, A in memory on little-endian
    const int stride = cairo_format_stride_for_width(CAIRO_FORMAT_RGB24, wPx);
    std::vector<unsigned char> pixels(static_cast<std::size_t>(stride) * hPx);
    for (int y = 0; y < hPx; ++y) std::copy_n(bgra.ptr<unsigned char>(y), 4 * wPx, &pixels[y * stride]);
    cairo_surface_t* surface =
        cairo_image_surface_create_for_data(pixels.data(), CAIRO_FORMAT_RGB24, wPx, hPx, stride);
    cairo_save(cr);
    cairo_translate(cr, box.x + (box.w - wMm) / 2, box.y + (box.h - hMm) / 2);
    cairo_scale(cr, wMm / wPx, hMm / hPx);
    cairo_set_source_surface(cr, surface, 0, 0);
    cairo_paint(cr);
    cairo_restore(cr);
    cairo_surface_finish(surface);  // the PDF surface has copied the pixels by now
    cairo_surface_destroy(surface);
}

// `text` centred on x at baseline y, at `sizeMm` or smaller so that it fits `maxWidth`.
void drawText(cairo_t* cr, const std::string& text, double centreX, double baseline, double sizeMm, double maxWidth,
              bool bold) {
    if (text.empty()) return;
    cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL, bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, sizeMm);
    cairo_text_extents_t e;
    cairo_text_extents(cr, text.c_str(), &e);
    if (e.x_advance > maxWidth) {
        cairo_set_font_size(cr, sizeMm * maxWidth / e.x_advance);
        cairo_text_extents(cr, text.c_str(), &e);
    }
    cairo_move_to(cr, centreX - e.x_advance / 2, baseline);
    cairo_show_text(cr, text.c_str());
}

// The QR code's dark modules as filled squares (vectors: every module exactly the same size on paper), with the
// quiet zone left white, in a square of side `sideMm` at (x, y).
void drawQr(cairo_t* cr, const std::string& url, double x, double y, double sideMm) {
    const cv::Mat modules = encodeQrModules(url);
    const double module = sideMm / (modules.cols + 2 * kQrQuietModules);
    for (int r = 0; r < modules.rows; ++r)
        for (int c = 0; c < modules.cols; ++c)
            if (modules.at<unsigned char>(r, c))
                cairo_rectangle(cr, x + (c + kQrQuietModules) * module, y + (r + kQrQuietModules) * module, module,
                                module);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_fill(cr);
}

cairo_status_t appendTo(void* closure, const unsigned char* data, unsigned int length) {
    static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
    return CAIRO_STATUS_SUCCESS;
}

}  // namespace

CardContent readCardContent(const fs::path& keptFolder, const std::string& code, const std::string& shareUrl,
                            const PrintSettings& settings) {
    CardContent c;
    c.code = code;
    c.shareUrl = shareUrl;
    const fs::path preview = keptFolder / "preview_three_quarter.png";
    std::error_code ec;
    if (!fs::exists(preview, ec))
        throw BoothError(ErrorKind::BadInput, preview.string(), "no avatar preview: not a complete session folder");
    c.photoStyle = readPhoto(preview);
    c.character = readOptional(keptFolder / "preview_character.png");
    c.toon = readOptional(keptFolder / "toon" / "turntable_000.png");
    if (settings.frontPhoto) c.frontPhoto = readOptional(keptFolder / "front.jpg");
    return c;
}

std::string renderCardPdf(const CardContent& content, const PrintSettings& settings) {
    const double W = settings.widthMm, H = settings.heightMm;
    std::string pdf;
    cairo_surface_t* surface = cairo_pdf_surface_create_for_stream(appendTo, &pdf, W * kPointsPerMm, H * kPointsPerMm);
    Context context(cairo_create(surface), cairo_destroy);
    cairo_t* cr = context.get();
    cairo_scale(cr, kPointsPerMm, kPointsPerMm);  // from here on, millimetres
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);

    // Top to bottom: the title, the photo style large, the other pictures in a row, then the code and the QR code.
    const double margin = 0.06 * std::min(W, H);
    const double gap = 0.02 * std::min(W, H);
    const double inner = W - 2 * margin;
    const double titleSize = 0.055 * H;
    const double band = std::min(0.3 * W, 0.2 * H);  // the code and QR code band's height (the QR code's side)
    double y = margin;
    if (!settings.title.empty()) {
        cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
        drawText(cr, settings.title, W / 2, y + titleSize * 0.8, titleSize, inner, true);
        y += titleSize + gap;
    }
    const double pictures = H - margin - band - gap - y;  // the height left for the pictures
    std::vector<const cv::Mat*> row;
    for (const cv::Mat* m : {&content.character, &content.toon, &content.frontPhoto})
        if (!m->empty()) row.push_back(m);
    const double count = static_cast<double>(row.size());
    const double rowGaps = gap * (row.empty() ? 0.0 : count - 1);
    const double small = row.empty() ? 0.0 : std::min((inner - rowGaps) / count, 0.4 * pictures);
    const double large = std::min(inner, pictures - (row.empty() ? 0.0 : small + gap));
    drawPicture(cr, content.photoStyle, {(W - large) / 2, y, large, large}, settings.dpi);
    y += large + gap;
    double x = (W - (small * count + rowGaps)) / 2;
    for (const cv::Mat* m : row) {
        drawPicture(cr, *m, {x, y, small, small}, settings.dpi);
        x += small + gap;
    }

    // The band: "your code" and the code on the left, the QR code of the visitor's page on the right (the code
    // alone, centred, when there is no page).
    const double bandTop = H - margin - band;
    const bool qr = !content.shareUrl.empty();
    const double textWidth = qr ? inner - band - gap : inner;
    const double textCentre = margin + textWidth / 2;
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
    drawText(cr, qr ? "Scan for your 3-D avatar" : "Your code", textCentre, bandTop + 0.22 * band, 0.13 * band,
             textWidth, false);
    cairo_set_source_rgb(cr, 0, 0, 0);
    drawText(cr, content.code, textCentre, bandTop + 0.68 * band, 0.36 * band, textWidth, true);
    if (qr) drawQr(cr, content.shareUrl, W - margin - band, bandTop, band);

    context.reset();
    cairo_surface_finish(surface);
    const cairo_status_t status = cairo_surface_status(surface);
    cairo_surface_destroy(surface);
    if (status != CAIRO_STATUS_SUCCESS)
        throw BoothError(ErrorKind::Internal, "", std::string("the card's PDF: ") + cairo_status_to_string(status));
    return pdf;
}

}  // namespace avatarbooth
