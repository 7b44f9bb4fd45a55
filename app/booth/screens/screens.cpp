// Drawing each booth screen (see screens.h): layout bands, the mirrored preview with its oval, texts and labels.
#include "booth/screens/screens.h"

#include "booth/screens/qr_code.h"
#include "common/error.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <ctime>

namespace avatarbooth {

namespace {

// Colours (BGR).
const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kSoftWhite(235, 235, 235);
const cv::Scalar kGrey(170, 170, 170);
const cv::Scalar kInk(40, 30, 25);
const cv::Scalar kAccent(40, 175, 255);      // warm amber: titles
const cv::Scalar kStartGreen(90, 190, 60);   // the Start button's colour
const cv::Scalar kRetakeRed(70, 70, 225);    // the Retake button's colour
const cv::Scalar kReady(110, 230, 90);       // the oval when the guide says "hold still"
const cv::Scalar kErrorBand(45, 45, 185);
const cv::Scalar kCameraBand(0, 120, 215);
const cv::Scalar kTopBg(70, 38, 24), kBottomBg(28, 14, 10);  // the background gradient
const cv::Scalar kOperatorBg(48, 48, 48);

// A head in profile, nose towards +x, in a unit box (x right, y down): back of the neck up over the crown,
// down the forehead, nose, lips and chin, to the front of the neck. Drawn as the side guide's outline.
const cv::Point2d kProfile[] = {
    {0.30, 1.00}, {0.27, 0.88}, {0.20, 0.76}, {0.15, 0.56}, {0.16, 0.36}, {0.24, 0.17}, {0.38, 0.06},
    {0.55, 0.02}, {0.70, 0.06}, {0.80, 0.16}, {0.84, 0.30}, {0.82, 0.37}, {0.86, 0.45}, {0.93, 0.53},
    {0.86, 0.57}, {0.87, 0.62}, {0.84, 0.66}, {0.86, 0.70}, {0.82, 0.75}, {0.84, 0.80}, {0.78, 0.86},
    {0.64, 0.88}, {0.62, 1.00}};

void blendRect(cv::Mat& canvas, cv::Rect r, const cv::Scalar& colour, double alpha) {
    r &= cv::Rect(0, 0, canvas.cols, canvas.rows);
    if (r.empty()) return;
    cv::Mat roi = canvas(r);
    roi = roi * (1.0 - alpha) + colour * alpha;
}

void fillRounded(cv::Mat& canvas, cv::Rect r, int radius, const cv::Scalar& colour) {
    radius = std::min({radius, r.width / 2, r.height / 2});
    cv::rectangle(canvas, cv::Rect(r.x + radius, r.y, r.width - 2 * radius, r.height), colour, cv::FILLED);
    cv::rectangle(canvas, cv::Rect(r.x, r.y + radius, r.width, r.height - 2 * radius), colour, cv::FILLED);
    for (const cv::Point c : {cv::Point(r.x + radius, r.y + radius), cv::Point(r.br().x - radius - 1, r.y + radius),
                              cv::Point(r.x + radius, r.br().y - radius - 1),
                              cv::Point(r.br().x - radius - 1, r.br().y - radius - 1)})
        cv::circle(canvas, c, radius, colour, cv::FILLED, cv::LINE_AA);
}

std::string formatBytes(std::uintmax_t bytes) {
    const double b = static_cast<double>(bytes);
    if (b >= 1e9) return cv::format("%.1f GB", b / 1e9);
    if (b >= 1e6) return cv::format("%.0f MB", b / 1e6);
    return cv::format("%.0f kB", b / 1e3);
}

std::string formatLocalTime(WallTime t) {
    const std::time_t tt = std::chrono::system_clock::to_time_t(t);
    std::tm tm{};
    localtime_r(&tt, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M", &tm);
    return buf;
}

// The centre of a photo cut to the shape of the box it is shown in (no narrower than 3:5), so that a thumbnail
// uses its box's height on a portrait screen rather than shrinking to a strip.
cv::Mat cropToAspect(const cv::Mat& photo, cv::Rect box) {
    const double aspect = std::max(0.6, static_cast<double>(box.width) / std::max(1, box.height));
    if (photo.cols <= aspect * photo.rows) return photo;
    const int w = static_cast<int>(aspect * photo.rows);
    return photo(cv::Rect((photo.cols - w) / 2, 0, w, photo.rows));
}

std::string hintKey(Hint h) { return std::string("hint.") + toString(h); }

std::string bannerKey(const ScreenModel& m) {
    switch (m.banner) {
        case BannerKind::None: return "";
        case BannerKind::CameraLost: return "error.camera_lost.title";
        case BannerKind::CaptureFailed: return "error.capture_failed";
        case BannerKind::SaveFailed: return "error.save_failed";
        case BannerKind::FitFailed:
            switch (m.fitFailure) {
                case FitFailure::NoFace: return "error.fit.no_face";
                case FitFailure::NotProfile: return "error.fit.not_profile";
                case FitFailure::TurnMore: return "error.fit.turn_more";
                case FitFailure::TurnBack: return "error.fit.turn_back";
                case FitFailure::FaceHidden: return "error.fit.face_hidden";
                case FitFailure::Mismatch: return "error.fit.mismatch";
                case FitFailure::Other: return "error.fit.other";
            }
    }
    return "error.fit.other";
}

}  // namespace

ScreenRenderer::ScreenRenderer(ScreenSettings settings)
    : settings_(std::move(settings)),
      strings_(StringTable::load(settings_.stringsFile.empty() ? StringTable::defaultFile() : settings_.stringsFile)) {
    const cv::Size s = settings_.size;
    if (s.width < 320 || s.height < 240 || s.width > 8192 || s.height > 8192)
        throw BoothError(ErrorKind::BadConfig, "screen.size",
                         cv::format("%dx%d is not a usable screen size (320x240 to 8192x8192)", s.width, s.height));
    text_ = std::make_unique<TextRenderer>(resolveFonts(settings_.fonts), settings_.language);

    const int W = s.width, H = s.height;
    ScreenLayout& L = layout_;
    L.unit = std::min(W, H) / 720.0;
    const int margin = static_cast<int>(std::lround(32 * L.unit));
    auto rows = [&](double y0, double y1) {
        return cv::Rect(0, static_cast<int>(std::lround(y0 * H)), W,
                        static_cast<int>(std::lround(y1 * H)) - static_cast<int>(std::lround(y0 * H)));
    };
    L.top = rows(0.0, 0.13);
    L.banner = rows(0.14, 0.27);
    L.middle = rows(0.15, 0.80);
    L.bottom = rows(0.80, 1.0);
    const int half = W / 2;
    L.leftLabel = cv::Rect(margin, L.bottom.y + margin / 2, half - margin - margin / 2, L.bottom.height - margin);
    L.rightLabel = cv::Rect(half + margin / 2, L.leftLabel.y, L.leftLabel.width, L.leftLabel.height);
    const int codeW = std::min(W - 2 * margin, static_cast<int>(std::lround(620 * L.unit)));
    const cv::Rect codeRows = rows(0.40, 0.64);
    L.code = cv::Rect((W - codeW) / 2, codeRows.y, codeW, codeRows.height);
    // With a QR code: the code in the left half and the QR code in the right half of the middle band (landscape),
    // or the code under the title and the QR code under it (portrait). The QR code takes as much of the screen as
    // the layout leaves it: to be scanned from 1 m a code should be about 10 cm wide (a tenth of the distance),
    // which a 1280x720 panel of 15" (19 cm tall) gives at 0.52 of its height.
    if (W >= H) {
        const int side = std::min(L.middle.height, W / 2 - 2 * margin);
        L.qr = cv::Rect(W / 2 + (W / 2 - side) / 2, L.middle.y + (L.middle.height - side) / 2, side, side);
        const int w = std::min(W / 2 - 2 * margin, static_cast<int>(std::lround(560 * L.unit)));
        L.codeBesideQr = cv::Rect(W / 4 - w / 2, codeRows.y, w, codeRows.height);
    } else {
        const cv::Rect codeBand = rows(0.24, 0.34);
        L.codeBesideQr = cv::Rect((W - codeW) / 2, codeBand.y, codeW, codeBand.height);
        const int top = static_cast<int>(std::lround(0.37 * H));
        const int side = std::min(W - 2 * margin, L.bottom.y - top - margin);
        L.qr = cv::Rect((W - side) / 2, top, side, side);
    }
    const int barW = std::min(W - 2 * margin, static_cast<int>(std::lround(760 * L.unit)));
    const int barH = std::max(8, static_cast<int>(std::lround(26 * L.unit)));
    L.progress = cv::Rect((W - barW) / 2, static_cast<int>(std::lround(0.66 * H)), barW, barH);
    // The stage lies under the avatars' lower half, across the whole width: the heads stand on it.
    L.stage = rows(0.40, 0.80);

    // The background: a vertical gradient, made once.
    background_.create(s, CV_8UC3);
    for (int y = 0; y < H; ++y) {
        const double t = static_cast<double>(y) / std::max(1, H - 1);
        background_.row(y).setTo(kTopBg * (1.0 - t) + kBottomBg * t);
    }
    canvas_.create(s, CV_8UC3);
}

ScreenRenderer::~ScreenRenderer() = default;

cv::Point2d ScreenRenderer::previewToScreen(cv::Point2d p, cv::Size frame) const {
    const double W = settings_.size.width, H = settings_.size.height;
    const double s = std::max(W / frame.width, H / frame.height);
    return {W / 2 - (p.x - frame.width / 2.0) * s, H / 2 + (p.y - frame.height / 2.0) * s};
}

const cv::Mat& ScreenRenderer::draw(const ScreenModel& m, const ScreenInputs& in) {
    ScreenModel timeless = m;
    timeless.sinceEntered = Millis(0);
    if (m.id == ScreenId::Reveal && in.avatarVersion != 0 && revealShown_ &&
        revealShown_->avatarVersion == in.avatarVersion && revealShown_->model == timeless)
        return canvas_;  // the very picture drawn last time: the avatar holds its pose
    revealShown_.reset();
    switch (m.id) {
        case ScreenId::Attract: attract(m, in); break;
        case ScreenId::FrontGuide:
        case ScreenId::SideGuide: guide(m, in); break;
        case ScreenId::Countdown: countdown(m, in); break;
        case ScreenId::CaptureFlash: canvas_.setTo(kWhite); break;
        case ScreenId::Processing: processing(m); break;
        case ScreenId::Reveal: reveal(in); break;
        case ScreenId::RetakeChoice: retakeChoice(in); break;
        case ScreenId::Thanks: thanks(m); break;
        case ScreenId::CameraLost: cameraLost(m); break;
        case ScreenId::OperatorMenu: operatorMenu(m, in); break;
    }
    if (m.id != ScreenId::CameraLost && m.id != ScreenId::OperatorMenu && m.id != ScreenId::CaptureFlash)
        drawBanner(m);
    if (m.id == ScreenId::Reveal && in.avatarVersion != 0)
        revealShown_ = RevealShown{in.avatarVersion, timeless};
    return canvas_;
}

// ------------------------------------------------------------------------------------------------- helpers

void ScreenRenderer::drawBackground() { background_.copyTo(canvas_); }

void ScreenRenderer::drawText(const std::string& text, cv::Rect box, int px, cv::Scalar colour, FontWeight weight,
                              double alpha) {
    if (text.empty() || box.width <= 0 || box.height <= 0) return;
    // One line when a size of at least 70 % fits the width (a title or hint reads better unbroken); else wrapped,
    // and shrunk until the lines fit the box's height (a long translation must not spill out of its band).
    if (text.find('\n') == std::string::npos) {
        const int w = text_->measure(text, px, weight).width;
        if (w > box.width && w * 7 <= box.width * 10) px = std::max(10, px * box.width / w);
    }
    std::vector<std::string> lines;
    TextRenderer::Metrics m;
    for (;;) {
        lines = text_->wrap(text, px, box.width, weight);
        m = text_->measure("", px, weight);
        const int lineH = std::max(m.lineHeight, m.ascent + m.descent);
        if (static_cast<int>(lines.size()) * lineH <= box.height || px <= 10) break;
        px = std::max(10, static_cast<int>(px * 0.9));
    }
    const int lineH = std::max(m.lineHeight, m.ascent + m.descent);
    const int total = static_cast<int>(lines.size()) * lineH;
    int baseline = box.y + (box.height - total) / 2 + m.ascent + (lineH - m.ascent - m.descent) / 2;
    for (const auto& line : lines) {
        const int w = text_->measure(line, px, weight).width;
        text_->draw(canvas_, line, {box.x + (box.width - w) / 2, baseline}, px, colour, weight, alpha);
        baseline += lineH;
    }
}

void ScreenRenderer::drawButtonLabel(const std::string& text, cv::Rect box, bool startButton) {
    const double u = layout_.unit;
    const cv::Scalar colour = startButton ? kStartGreen : kRetakeRed;
    fillRounded(canvas_, box, static_cast<int>(24 * u), cv::Scalar(20, 12, 8));
    // The button's colour as a disc on the side of the label nearest the button's edge of the screen.
    const int r = std::max(6, static_cast<int>(std::min(box.height * 0.32, 34 * u)));
    const bool discLeft = box.x < settings_.size.width / 2;
    const int pad = static_cast<int>(20 * u);
    const cv::Point c(discLeft ? box.x + pad + r : box.br().x - pad - r, box.y + box.height / 2);
    cv::circle(canvas_, c, r, colour, cv::FILLED, cv::LINE_AA);
    cv::circle(canvas_, c, r, kWhite, std::max(1, static_cast<int>(3 * u)), cv::LINE_AA);
    const cv::Rect textBox = discLeft ? cv::Rect(c.x + r + pad, box.y, box.br().x - (c.x + r + pad) - pad, box.height)
                                      : cv::Rect(box.x + pad, box.y, c.x - r - 2 * pad - box.x, box.height);
    drawText(text, textBox, static_cast<int>(44 * u), kWhite, FontWeight::Bold);
}

void ScreenRenderer::drawImageFitted(const cv::Mat& image, cv::Rect box, bool mirror) {
    if (image.empty() || box.empty()) return;
    const double s = std::min(static_cast<double>(box.width) / image.cols, static_cast<double>(box.height) / image.rows);
    const cv::Size size(std::max(1, static_cast<int>(image.cols * s)), std::max(1, static_cast<int>(image.rows * s)));
    cv::Mat resized;
    if (size == image.size() && !mirror) {
        resized = image;  // rendered at the size shown (the avatar): nothing to scale
    } else {
        // Bilinear down to half size (4x cheaper than area averaging, and the images are photos and renders without
        // fine patterns); area averaging below that, where bilinear would alias.
        cv::resize(image, resized, size, 0, 0, s < 0.5 ? cv::INTER_AREA : cv::INTER_LINEAR);
    }
    if (mirror) cv::flip(resized, resized, 1);
    const cv::Rect at(box.x + (box.width - size.width) / 2, box.y + (box.height - size.height) / 2, size.width,
                      size.height);
    const cv::Rect clipped = at & cv::Rect(0, 0, canvas_.cols, canvas_.rows);
    if (clipped.empty()) return;
    const cv::Mat src = resized(clipped - at.tl());
    cv::Mat dst = canvas_(clipped);
    if (src.channels() == 3) {
        src.copyTo(dst);
    } else if (src.channels() == 4) {
        for (int y = 0; y < src.rows; ++y) {
            const uchar* s4 = src.ptr(y);
            uchar* d = dst.ptr(y);
            for (int x = 0; x < src.cols; ++x, s4 += 4, d += 3) {
                const int a = s4[3];
                if (a == 0) continue;  // most of an avatar's square is background
                for (int k = 0; k < 3; ++k) d[k] = static_cast<uchar>((s4[k] * a + d[k] * (255 - a) + 127) / 255);
            }
        }
    } else if (src.channels() == 1) {
        cv::cvtColor(src, dst, cv::COLOR_GRAY2BGR);
    }
}

void ScreenRenderer::drawProfileOutline(cv::Rect box, bool noseRight, cv::Scalar colour, int thickness) {
    std::vector<cv::Point2d> pts;
    for (const auto& p : kProfile)
        pts.emplace_back(box.x + (noseRight ? p.x : 1.0 - p.x) * box.width, box.y + p.y * box.height);
    // Chaikin's corner cutting, three rounds: the table's corners become the smooth curves of a face.
    for (int round = 0; round < 3; ++round) {
        std::vector<cv::Point2d> smooth{pts.front()};
        for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
            smooth.push_back(0.75 * pts[i] + 0.25 * pts[i + 1]);
            smooth.push_back(0.25 * pts[i] + 0.75 * pts[i + 1]);
        }
        smooth.push_back(pts.back());
        pts = std::move(smooth);
    }
    std::vector<cv::Point> poly;
    for (const auto& p : pts) poly.emplace_back(cvRound(p.x), cvRound(p.y));
    cv::polylines(canvas_, poly, false, colour, thickness, cv::LINE_AA);
}

void ScreenRenderer::drawPreview(const cv::Mat& preview, bool ready, bool profile) {
    const double u = layout_.unit;
    if (preview.empty()) {
        canvas_.setTo(cv::Scalar(30, 30, 30));  // the camera's first frame has not come yet
        return;
    }
    CV_Assert(preview.type() == CV_8UC3);
    const double W = canvas_.cols, H = canvas_.rows;
    const double s = std::max(W / preview.cols, H / preview.rows);
    // The part of the frame that fills the screen, then scaled, then mirrored.
    const double vw = W / s, vh = H / s;
    cv::Rect roi(cvRound((preview.cols - vw) / 2), cvRound((preview.rows - vh) / 2), cvRound(vw), cvRound(vh));
    roi &= cv::Rect(0, 0, preview.cols, preview.rows);
    cv::flip(preview(roi), scratch_, 1);  // on the small frame: a quarter of the work of flipping the screen
    cv::resize(scratch_, canvas_, canvas_.size(), 0, 0, cv::INTER_LINEAR);

    const cv::Rect2d oval = ovalBox(settings_.oval, preview.size());
    const cv::Point2d centre = previewToScreen({oval.x + oval.width / 2, oval.y + oval.height / 2}, preview.size());
    const cv::Size axes(cvRound(oval.width * s / 2), cvRound(oval.height * s / 2));
    if (outsideOvalFor_ != preview.size()) {
        outsideOval_.create(canvas_.size(), CV_8U);
        outsideOval_.setTo(255);
        cv::ellipse(outsideOval_, cv::Point(cvRound(centre.x), cvRound(centre.y)), axes, 0, 0, 360, 0, cv::FILLED,
                    cv::LINE_8);
        outsideOvalFor_ = preview.size();
    }
    canvas_.convertTo(dimmed_, -1, 0.4);
    dimmed_.copyTo(canvas_, outsideOval_);
    const cv::Scalar ring = ready ? kReady : kWhite;
    const int thick = std::max(2, static_cast<int>(5 * u));
    if (profile) {
        // The outline's head (crown to chin, 0.86 of its box) spans the oval; its neck runs on below.
        const int h = cvRound(axes.height * 2 / 0.86), w = cvRound(h * 0.8);
        drawProfileOutline(cv::Rect(cvRound(centre.x) - w / 2, cvRound(centre.y) - axes.height, w, h),
                           /*noseRight=*/true, ring, thick);
        cv::ellipse(canvas_, cv::Point(cvRound(centre.x), cvRound(centre.y)), axes, 0, 0, 360, ring,
                    std::max(1, thick / 3), cv::LINE_AA);
    } else {
        cv::ellipse(canvas_, cv::Point(cvRound(centre.x), cvRound(centre.y)), axes, 0, 0, 360, ring, thick,
                    cv::LINE_AA);
    }
}

void ScreenRenderer::drawBanner(const ScreenModel& m) {
    const std::string key = bannerKey(m);
    if (key.empty()) return;
    const cv::Scalar band = m.banner == BannerKind::CameraLost ? kCameraBand : kErrorBand;
    blendRect(canvas_, layout_.banner, band, 0.88);
    const int pad = static_cast<int>(24 * layout_.unit);
    const cv::Rect box(layout_.banner.x + pad, layout_.banner.y + pad / 3, layout_.banner.width - 2 * pad,
                       layout_.banner.height - 2 * pad / 3);
    drawText(str(key), box, static_cast<int>(40 * layout_.unit), kWhite, FontWeight::Bold);
}

// --------------------------------------------------------------------------------------------------- screens

cv::Rect ScreenRenderer::avatarArea(ScreenId screen) const {
    const ScreenLayout& L = layout_;
    if (screen == ScreenId::Attract) {
        const int y = L.top.br().y + static_cast<int>(0.07 * canvas_.rows);  // under the subtitle
        return cv::Rect(L.middle.x, y, L.middle.width, L.middle.br().y - y);
    }
    return cv::Rect(L.middle.x, L.top.br().y, L.middle.width, L.middle.br().y - L.top.br().y);
}

std::vector<cv::Rect> ScreenRenderer::avatarImageBoxes(ScreenId screen, int count) const {
    std::vector<cv::Rect> boxes = avatarCells(avatarArea(screen), count);
    if (count > 1)
        for (cv::Rect& b : boxes) b.height = std::max(0, b.height - labelHeight());
    return boxes;
}

std::vector<cv::Rect> ScreenRenderer::avatarCells(cv::Rect area, int count) {
    std::vector<cv::Rect> cells;
    if (count <= 0 || area.empty()) return cells;
    if (count == 1) return {area};
    if (area.width >= area.height) {
        // Widths: 1.25 for the first, 1 for the others; positions: first in the middle, then left, right, ...
        const double unit = area.width / (count + 0.25);
        std::vector<int> order(static_cast<std::size_t>(count));  // left-to-right slot -> avatar index
        const int middle = (count - 1) / 2;
        order[static_cast<std::size_t>(middle)] = 0;
        int left = middle - 1, right = middle + 1;
        for (int i = 1; i < count; ++i) {
            const bool goLeft = (i % 2 == 1 && left >= 0) || right >= count;
            order[static_cast<std::size_t>(goLeft ? left-- : right++)] = i;
        }
        cells.resize(static_cast<std::size_t>(count));
        double x = area.x;
        for (int slot = 0; slot < count; ++slot) {
            const int i = order[static_cast<std::size_t>(slot)];
            const double w = unit * (i == 0 ? 1.25 : 1.0);
            cells[static_cast<std::size_t>(i)] =
                cv::Rect(static_cast<int>(std::lround(x)), area.y, static_cast<int>(std::lround(x + w) - std::lround(x)),
                         area.height);
            x += w;
        }
        return cells;
    }
    const int topH = area.height * 2 / 3;
    cells.emplace_back(area.x, area.y, area.width, topH);
    const int others = count - 1;
    for (int i = 0; i < others; ++i) {
        const int x0 = area.x + area.width * i / others, x1 = area.x + area.width * (i + 1) / others;
        cells.emplace_back(x0, area.y + topH, x1 - x0, area.height - topH);
    }
    return cells;
}

void ScreenRenderer::drawAvatars(const ScreenInputs& in, ScreenId screen) {
    const double u = layout_.unit;
    if (!in.stage.empty()) drawImageFitted(in.stage, layout_.stage);
    const cv::Rect area = avatarArea(screen);
    if (in.avatars.empty()) {
        drawImageFitted(in.avatar, area);
        return;
    }
    const std::vector<cv::Rect> cells = avatarCells(area, static_cast<int>(in.avatars.size()));
    const bool labelled = in.avatars.size() > 1;
    for (std::size_t i = 0; i < in.avatars.size(); ++i) {
        const StyledAvatar& a = in.avatars[i];
        cv::Rect cell = cells[i];
        const int labelH = labelled ? labelHeight() : 0;
        const cv::Rect label(cell.x, cell.br().y - labelH, cell.width, labelH);
        cell.height -= labelH;
        if (a.image.empty()) {
            drawText(str("style.making"), cell, static_cast<int>(30 * u), kGrey);
        } else {
            drawImageFitted(a.image, cell);
        }
        const std::string key = "style." + a.style;
        if (labelled && strings_.has(settings_.language, key))
            drawText(str(key), label, static_cast<int>(28 * u), kSoftWhite, FontWeight::Bold);
    }
}

void ScreenRenderer::attract(const ScreenModel& m, const ScreenInputs& in) {
    const double u = layout_.unit;
    drawBackground();
    const ScreenLayout& L = layout_;
    const cv::Rect titleBox(L.top.x, L.top.y + static_cast<int>(10 * u), L.top.width, L.top.height);
    drawText(str("title"), titleBox, static_cast<int>(72 * u), kAccent, FontWeight::Bold);
    const cv::Rect sub(L.top.x, L.top.br().y, L.top.width, static_cast<int>(0.07 * canvas_.rows));
    drawText(str("attract.subtitle"), sub, static_cast<int>(36 * u), kSoftWhite);
    drawAvatars(in, ScreenId::Attract);
    // The prompt pulses gently (never disappears: a visitor glancing at the screen always sees it).
    const double phase = static_cast<double>(m.sinceEntered.count() % 1600) / 1600.0;
    const double alpha = 0.75 + 0.25 * std::cos(2 * CV_PI * phase);
    const int margin = static_cast<int>(32 * u);
    const cv::Rect pill(L.bottom.x + margin, L.bottom.y + margin / 2, L.bottom.width - 2 * margin,
                        L.bottom.height - margin);
    fillRounded(canvas_, pill, pill.height / 2, cv::Scalar(20, 12, 8));
    const int r = std::max(6, static_cast<int>(pill.height * 0.3));
    const cv::Point disc(pill.x + pill.height / 2, pill.y + pill.height / 2);
    cv::circle(canvas_, disc, r, kStartGreen, cv::FILLED, cv::LINE_AA);
    drawText(str("attract.press"),
             cv::Rect(disc.x + r + margin / 2, pill.y, pill.br().x - disc.x - r - margin, pill.height),
             static_cast<int>(48 * u), kWhite, FontWeight::Bold, alpha);
}

void ScreenRenderer::guide(const ScreenModel& m, const ScreenInputs& in) {
    const double u = layout_.unit;
    const bool front = m.id == ScreenId::FrontGuide;
    drawPreview(in.preview, m.hint == Hint::HoldStill, !front);
    const ScreenLayout& L = layout_;
    blendRect(canvas_, L.top, cv::Scalar(0, 0, 0), 0.55);
    drawText(str(front ? "guide.front.step" : "guide.side.step"), L.top, static_cast<int>(40 * u), kSoftWhite,
             FontWeight::Bold);
    blendRect(canvas_, L.bottom, cv::Scalar(0, 0, 0), 0.6);
    const Hint hint = m.hint == Hint::None ? (front ? Hint::None : Hint::TurnRight) : m.hint;
    const int pad = static_cast<int>(24 * u);
    const cv::Rect hintBox(L.bottom.x + pad, L.bottom.y, L.bottom.width - 2 * pad, L.bottom.height * 2 / 3);
    drawText(str(hintKey(hint)), hintBox, static_cast<int>(56 * u), hint == Hint::HoldStill ? kReady : kWhite,
             FontWeight::Bold);
    const cv::Rect pressBox(hintBox.x, hintBox.br().y, hintBox.width, L.bottom.br().y - hintBox.br().y);
    drawText(str("guide.press_now"), pressBox, static_cast<int>(30 * u), kGrey);
    if (!front && m.hint != Hint::HoldStill && !in.preview.empty()) {
        // An arrow towards where the visitor turns (their right: the mirrored preview's right; back towards the
        // camera, the other way, when turned past the profile or the face is hidden), beside the oval when there is
        // room, else above the hint.
        const cv::Rect2d oval = ovalBox(settings_.oval, in.preview.size());
        const double ovalRight = previewToScreen({oval.x, oval.y + oval.height / 2}, in.preview.size()).x;
        const int gap = static_cast<int>(24 * u), want = static_cast<int>(std::min(canvas_.cols, canvas_.rows) * 0.2);
        const int room = canvas_.cols - static_cast<int>(ovalRight) - 2 * gap;
        cv::Point a, b;
        if (room >= want / 2) {
            a = cv::Point(static_cast<int>(ovalRight) + gap, L.middle.y + L.middle.height / 2);
            b = a + cv::Point(std::min(want, room), 0);
        } else {
            a = cv::Point(canvas_.cols / 2 - want / 2, L.bottom.y - static_cast<int>(60 * u));
            b = a + cv::Point(want, 0);
        }
        if (hint == Hint::TurnBack || hint == Hint::FaceHidden) std::swap(a, b);
        cv::arrowedLine(canvas_, a, b, kAccent, std::max(3, static_cast<int>(10 * u)), cv::LINE_AA, 0, 0.35);
    }
}

void ScreenRenderer::countdown(const ScreenModel& m, const ScreenInputs& in) {
    const double u = layout_.unit;
    drawPreview(in.preview, true, m.photo == Photo::Side);
    const std::string n = std::to_string(std::max(0, m.countdown));
    const int px = static_cast<int>(std::min(canvas_.cols, canvas_.rows) * 0.5);
    // The number and a dark halo around it (so it reads over any face or backdrop), as coverage masks made once
    // per number: a glyph this big costs 9 blends a frame when the halo is drawn as offset copies.
    const std::string key = n + "@" + std::to_string(px);
    auto it = bigText_.find(key);
    if (it == bigText_.end()) {
        const auto metrics = text_->measure(n, px, FontWeight::Bold);
        const int halo = std::max(2, static_cast<int>(8 * u));
        cv::Mat ink(metrics.ascent + metrics.descent + 2 * halo, metrics.width + 2 * halo, CV_8UC3, cv::Scalar::all(0));
        text_->draw(ink, n, {halo, halo + metrics.ascent}, px, kWhite, FontWeight::Bold);
        BigText t;
        cv::extractChannel(ink, t.text, 0);
        cv::dilate(t.text, t.halo, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * halo + 1, 2 * halo + 1}));
        t.originOffset = {-halo, -halo - metrics.ascent};
        t.width = metrics.width;
        t.ascent = metrics.ascent;
        it = bigText_.emplace(key, std::move(t)).first;
    }
    const BigText& t = it->second;
    const cv::Point origin((canvas_.cols - t.width) / 2, canvas_.rows / 2 + t.ascent * 7 / 20);
    const cv::Rect at(origin + t.originOffset, t.text.size());
    const cv::Rect clipped = at & cv::Rect(0, 0, canvas_.cols, canvas_.rows);
    for (int y = clipped.y; y < clipped.br().y; ++y) {
        const uchar* tx = t.text.ptr(y - at.y) + (clipped.x - at.x);
        const uchar* ha = t.halo.ptr(y - at.y) + (clipped.x - at.x);
        uchar* d = canvas_.ptr(y) + 3 * clipped.x;
        for (int x = 0; x < clipped.width; ++x, d += 3) {
            if (ha[x] == 0) continue;
            const int keep = 255 * 255 - ha[x] * 153;  // the halo darkens by up to 60 %
            const int white = tx[x] * 235;             // the number is 92 % white over it
            for (int k = 0; k < 3; ++k) {
                const int dark = d[k] * keep / (255 * 255);
                d[k] = static_cast<uchar>(dark + (255 - dark) * white / (255 * 255));
            }
        }
    }
}

void ScreenRenderer::processing(const ScreenModel& m) {
    const double u = layout_.unit;
    drawBackground();
    const ScreenLayout& L = layout_;
    drawText(str("processing.title"), L.top + cv::Point(0, static_cast<int>(20 * u)), static_cast<int>(60 * u),
             kAccent, FontWeight::Bold);
    // A turning arc: the booth is alive even when a stage takes long.
    const cv::Point c(canvas_.cols / 2, static_cast<int>(canvas_.rows * 0.43));
    const int r = static_cast<int>(std::min(canvas_.cols, canvas_.rows) * 0.12);
    const double start = std::fmod(static_cast<double>(m.sinceEntered.count()) * 0.36, 360.0);
    cv::circle(canvas_, c, r, cv::Scalar(90, 60, 45), std::max(3, static_cast<int>(14 * u)), cv::LINE_AA);
    cv::ellipse(canvas_, c, {r, r}, start, 0, 100, kAccent, std::max(3, static_cast<int>(14 * u)), cv::LINE_AA);
    const cv::Rect bar = L.progress;
    fillRounded(canvas_, bar, bar.height / 2, cv::Scalar(90, 60, 45));
    const int filled = static_cast<int>(std::lround(std::clamp(m.progress, 0.0, 1.0) * bar.width));
    if (filled >= bar.height) fillRounded(canvas_, {bar.x, bar.y, filled, bar.height}, bar.height / 2, kAccent);
    const std::string key = m.fitStep ? std::string("stage.") + toString(*m.fitStep) : std::string();
    const bool known = !key.empty() && strings_.has(settings_.language, key);
    const cv::Rect stageBox(L.middle.x, bar.br().y + static_cast<int>(16 * u), L.middle.width,
                            static_cast<int>(70 * u));
    drawText(str(known ? key : "stage.working"), stageBox, static_cast<int>(40 * u), kSoftWhite);
}

void ScreenRenderer::reveal(const ScreenInputs& in) {
    if (revealLayer_.empty()) {
        // Text is the costly part of a screen (FreeType, wrapping): the reveal's title and buttons never change, so
        // they are drawn once (the avatars' places lie between them, never under them).
        const double u = layout_.unit;
        drawBackground();
        const ScreenLayout& L = layout_;
        drawText(str("reveal.title"), L.top + cv::Point(0, static_cast<int>(10 * u)), static_cast<int>(64 * u),
                 kAccent, FontWeight::Bold);
        const bool startLeft = settings_.startButtonOnLeft;
        drawButtonLabel(str("reveal.keep"), startLeft ? L.leftLabel : L.rightLabel, true);
        drawButtonLabel(str("reveal.retake"), startLeft ? L.rightLabel : L.leftLabel, false);
        canvas_.copyTo(revealLayer_);
    } else {
        revealLayer_.copyTo(canvas_);
    }
    drawAvatars(in, ScreenId::Reveal);
}

void ScreenRenderer::retakeChoice(const ScreenInputs& in) {
    const double u = layout_.unit;
    drawBackground();
    const ScreenLayout& L = layout_;
    drawText(str("retake.title"), L.top + cv::Point(0, static_cast<int>(10 * u)), static_cast<int>(56 * u), kAccent,
             FontWeight::Bold);
    const bool startLeft = settings_.startButtonOnLeft;
    const int margin = static_cast<int>(32 * u);
    const cv::Rect leftArea(margin, L.top.br().y + margin, canvas_.cols / 2 - 2 * margin,
                            L.bottom.y - L.top.br().y - 2 * margin);
    const cv::Rect rightArea(canvas_.cols / 2 + margin, leftArea.y, leftArea.width, leftArea.height);
    const cv::Rect frontArea = startLeft ? leftArea : rightArea, sideArea = startLeft ? rightArea : leftArea;
    // The photos when the kiosk passes them, else the guides' oval and profile as pictures of the two photos.
    if (!in.frontPhoto.empty()) {
        drawImageFitted(cropToAspect(in.frontPhoto, frontArea), frontArea, /*mirror=*/true);  // as seen in the guide
    } else {
        const int h = frontArea.height, w = static_cast<int>(h * settings_.oval.aspect);
        cv::ellipse(canvas_, (frontArea.tl() + frontArea.br()) / 2, {w / 2 - 4, h / 2 - 4}, 0, 0, 360, kSoftWhite,
                    std::max(2, static_cast<int>(5 * u)), cv::LINE_AA);
    }
    if (!in.sidePhoto.empty()) {
        drawImageFitted(cropToAspect(in.sidePhoto, sideArea), sideArea, /*mirror=*/true);
    } else {
        const int h = sideArea.height, w = static_cast<int>(h * 0.85);
        const cv::Point c = (sideArea.tl() + sideArea.br()) / 2;
        drawProfileOutline({c.x - w / 2, sideArea.y, w, h}, true, kSoftWhite, std::max(2, static_cast<int>(5 * u)));
    }
    drawButtonLabel(str("retake.front"), startLeft ? L.leftLabel : L.rightLabel, true);
    drawButtonLabel(str("retake.side"), startLeft ? L.rightLabel : L.leftLabel, false);
}

void ScreenRenderer::thanks(const ScreenModel& m) {
    const double u = layout_.unit;
    drawBackground();
    const ScreenLayout& L = layout_;
    drawText(str("thanks.title"), L.top + cv::Point(0, static_cast<int>(20 * u)), static_cast<int>(68 * u), kAccent,
             FontWeight::Bold);
    if (m.code.empty() && m.banner == BannerKind::SaveFailed) return;  // no code to show; the banner says why
    const bool withQr = !m.code.empty() && !m.shareUrl.empty();
    const cv::Rect codeBox = withQr ? L.codeBesideQr : L.code;
    const cv::Rect label(codeBox.x, codeBox.y - static_cast<int>(80 * u), codeBox.width, static_cast<int>(70 * u));
    drawText(str("thanks.code_label"), label, static_cast<int>(44 * u), kSoftWhite);
    fillRounded(canvas_, codeBox, static_cast<int>(28 * u), kSoftWhite);
    if (m.code.empty()) {
        drawText(str("thanks.saving"), codeBox, static_cast<int>(60 * u), kInk, FontWeight::Bold);
    } else {
        // Letters spaced out a little: a code is read (and copied) one character at a time.
        int px = static_cast<int>(codeBox.height * 0.62);
        const int inner = codeBox.width - static_cast<int>(48 * u);
        if (widestCodeLetterAt_ != px) {
            int widestWidth = -1;
            for (char c : kCodeAlphabet) {
                const int w = text_->measure(std::string(1, c), px, FontWeight::Bold).width;
                if (w > widestWidth) {
                    widestWidth = w;
                    widestCodeLetter_ = c;
                }
            }
            widestCodeLetterAt_ = px;
        }
        std::string spaced, widest;
        for (char c : m.code) {
            spaced += spaced.empty() ? std::string(1, c) : std::string(" ") + c;
            widest += widest.empty() ? std::string(1, widestCodeLetter_) : std::string(" ") + widestCodeLetter_;
        }
        // Sized so that the widest code of this length fits, so every code shows at one size (rather than one
        // size per code's width, which would also give the glyph cache a new size for most visitors).
        if (const int w = text_->measure(widest, px, FontWeight::Bold).width; w > inner) px = px * inner / w;
        drawText(spaced, codeBox, px, kInk, FontWeight::Bold);
    }
    if (m.code.empty()) return;
    if (!withQr) {
        const cv::Rect info(L.middle.x + static_cast<int>(32 * u), L.code.br().y + static_cast<int>(24 * u),
                            L.middle.width - static_cast<int>(64 * u), static_cast<int>(0.16 * canvas_.rows));
        drawText(str("thanks.instructions"), info, static_cast<int>(40 * u), kSoftWhite);
        return;
    }
    // The QR code: whole pixels per module, as large as L.qr allows, drawn once per session. (A URL no QR code
    // holds cannot come from a checked configuration; the screen would then show the code alone.)
    if (qrUrl_ != m.shareUrl) {
        try {
            const cv::Mat modules = encodeQrModules(m.shareUrl);
            const int perModule = std::max(1, L.qr.width / (modules.cols + 2 * kQrQuietModules));
            qrImage_ = drawQrCode(modules, perModule);
        } catch (const BoothError&) {
            qrImage_.release();
        }
        qrUrl_ = m.shareUrl;
    }
    if (qrImage_.empty()) return;
    const cv::Rect at(L.qr.x + (L.qr.width - qrImage_.cols) / 2, L.qr.y + (L.qr.height - qrImage_.rows) / 2,
                      qrImage_.cols, qrImage_.rows);
    qrImage_.copyTo(canvas_(at & cv::Rect(0, 0, canvas_.cols, canvas_.rows)));
    const bool landscape = canvas_.cols >= canvas_.rows;
    const cv::Rect info = landscape ? cv::Rect(codeBox.x, codeBox.br().y + static_cast<int>(24 * u), codeBox.width,
                                               L.middle.br().y - codeBox.br().y - static_cast<int>(24 * u))
                                    : cv::Rect(L.middle.x + static_cast<int>(32 * u), at.br().y,
                                               L.middle.width - static_cast<int>(64 * u), L.bottom.br().y - at.br().y);
    if (info.height > 0) drawText(str("thanks.scan"), info, static_cast<int>(36 * u), kSoftWhite);
}

void ScreenRenderer::cameraLost(const ScreenModel& m) {
    const double u = layout_.unit;
    drawBackground();
    const int W = canvas_.cols, H = canvas_.rows;
    // A camera, crossed out.
    const int bw = static_cast<int>(std::min(W, H) * 0.34), bh = bw * 2 / 3;
    const cv::Rect body(W / 2 - bw / 2, static_cast<int>(H * 0.34) - bh / 2, bw, bh);
    const int thick = std::max(3, static_cast<int>(10 * u));
    fillRounded(canvas_, body, bh / 6, cv::Scalar(110, 100, 95));
    cv::rectangle(canvas_, cv::Rect(body.x + bw / 8, body.y - bh / 6, bw / 4, bh / 6 + 2), cv::Scalar(110, 100, 95),
                  cv::FILLED);
    cv::circle(canvas_, (body.tl() + body.br()) / 2, bh / 3, cv::Scalar(50, 40, 35), cv::FILLED, cv::LINE_AA);
    cv::line(canvas_, body.tl() - cv::Point(bw / 10, bh / 4), body.br() + cv::Point(bw / 10, bh / 8), kRetakeRed,
             thick, cv::LINE_AA);
    drawText(str("error.camera_lost.title"), {0, static_cast<int>(H * 0.56), W, static_cast<int>(H * 0.11)},
             static_cast<int>(56 * u), kWhite, FontWeight::Bold);
    drawText(str("error.camera_lost.body"), {0, static_cast<int>(H * 0.68), W, static_cast<int>(H * 0.1)},
             static_cast<int>(40 * u), kSoftWhite);
    // The technical reason, small, for the staff.
    drawText(m.detail, {0, static_cast<int>(H * 0.9), W, static_cast<int>(H * 0.07)}, static_cast<int>(22 * u),
             kGrey);
}

void ScreenRenderer::operatorMenu(const ScreenModel& m, const ScreenInputs& in) {
    const double u = layout_.unit;
    canvas_.setTo(kOperatorBg);
    const int W = canvas_.cols, H = canvas_.rows;
    const int margin = static_cast<int>(40 * u);
    const OperatorInfo& info = in.operatorInfo;
    drawText(str("operator.title"), {0, static_cast<int>(16 * u), W, static_cast<int>(80 * u)},
             static_cast<int>(52 * u), kAccent, FontWeight::Bold);
    const int rowH = static_cast<int>(std::min(0.1 * H, 84 * u));
    int y = static_cast<int>(0.17 * H);
    if (m.menuPage == OperatorPage::Menu) {
        const char* items[kOperatorItemCount] = {"operator.item.last_codes", "operator.item.free_disk",
                                                 "operator.item.exit"};
        for (int i = 0; i < kOperatorItemCount; ++i) {
            const cv::Rect row(margin, y, W - 2 * margin, rowH - static_cast<int>(10 * u));
            const bool selected = static_cast<int>(m.menuItem) == i;
            if (selected) fillRounded(canvas_, row, static_cast<int>(12 * u), kAccent);
            drawText(str(items[i]), row, static_cast<int>(40 * u), selected ? kInk : kSoftWhite, FontWeight::Bold);
            y += rowH;
        }
        y += rowH / 2;
        // One line each: the camera, the sessions, the disk, the printer (when on), the screen (when it came back
        // after going dark: a loose cable, a monitor on a timer; the operator learns of it only here and in the log,
        // since the booth went on without it). Five lines are set closer, to stay above the help line.
        std::vector<std::pair<std::string, cv::Scalar>> status = {
            {str(m.cameraAvailable ? "operator.camera_ok" : "operator.camera_lost"), kGrey},
            {strings_.format(settings_.language, "operator.sessions", {{"count", std::to_string(info.sessionsStored)}}), kGrey},
            {strings_.format(settings_.language, "operator.free", {{"free", formatBytes(info.freeBytes)}}), kGrey}};
        if (!info.printer.empty())
            status.emplace_back(strings_.format(settings_.language, "operator.printer", {{"state", info.printer}}),
                                info.printerProblem ? kRetakeRed : kGrey);
        if (info.screenRecoveries > 0)
            status.emplace_back(strings_.format(settings_.language, "operator.screen_back",
                                                {{"count", std::to_string(info.screenRecoveries)}}),
                                kGrey);
        const int lineH = static_cast<int>(rowH * (status.size() > 4 ? 0.6 : 0.7));
        for (const auto& [text, colour] : status) {
            drawText(text, {margin, y, W - 2 * margin, lineH}, static_cast<int>(30 * u), colour);
            y += lineH;
        }
        drawText(str("operator.help"), {0, H - static_cast<int>(80 * u), W, static_cast<int>(60 * u)},
                 static_cast<int>(30 * u), kSoftWhite);
        return;
    }
    if (m.menuPage == OperatorPage::LastCodes) {
        if (info.recentCodes.empty()) {
            drawText(str("operator.no_sessions"), {margin, y, W - 2 * margin, rowH}, static_cast<int>(36 * u),
                     kSoftWhite);
        }
        // Two columns on a landscape screen, one on a portrait one.
        const int columns = W > H ? 2 : 1;
        const int perColumn = columns == 2 ? 5 : 10;
        const int colW = (W - 2 * margin) / columns;
        const int lineH = static_cast<int>(std::min((H * 0.62) / perColumn, 70 * u));
        for (std::size_t i = 0; i < std::min<std::size_t>(info.recentCodes.size(), 10); ++i) {
            const int col = static_cast<int>(i) / perColumn, row = static_cast<int>(i) % perColumn;
            const cv::Rect cell(margin + col * colW, y + row * lineH, colW, lineH);
            const auto& [code, when] = info.recentCodes[i];
            drawText(code + "   " + formatLocalTime(when), cell, static_cast<int>(34 * u), kSoftWhite,
                     FontWeight::Bold);
        }
    } else {
        const RetentionReport& r = info.lastFreed;
        drawText(strings_.format(settings_.language, "operator.freed",
                                 {{"photos", std::to_string(r.photosDeleted)},
                                  {"sessions", std::to_string(r.sessionsDeleted)},
                                  {"freed", formatBytes(r.bytesFreed)}}),
                 {margin, y, W - 2 * margin, rowH * 2}, static_cast<int>(36 * u), kSoftWhite);
        drawText(strings_.format(settings_.language, "operator.free", {{"free", formatBytes(info.freeBytes)}}),
                 {margin, y + 2 * rowH, W - 2 * margin, rowH}, static_cast<int>(36 * u), kSoftWhite);
    }
    drawText(str("operator.back"), {0, H - static_cast<int>(80 * u), W, static_cast<int>(60 * u)},
             static_cast<int>(30 * u), kGrey);
}

}  // namespace avatarbooth
