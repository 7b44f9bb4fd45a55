// The booth's screens, drawn into a BGR image of the screen's size from the flow's ScreenModel plus the images
// and figures the kiosk holds (preview frame, avatar, photos, operator figures). Landscape and portrait screens
// share one layout in fractions of the screen, with text sizes scaled by its shorter side.
#pragma once

#include "booth/flow_types.h"
#include "booth/guidance.h"
#include "booth/session_store.h"
#include "booth/screens/strings.h"
#include "booth/screens/text_renderer.h"
#include "reveal/styles/reveal_styles.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth {

struct ScreenSettings {
    // The screen in pixels as the visitor sees it (after any rotation by the display): 1280x720, or a portrait
    // screen such as 720x1280.
    cv::Size size{1280, 720};
    // The language of every text ("en" or "ja" in the configuration).
    Language language = Language::English;
    // Font files; empty fields are Debian's DejaVu Sans / DejaVu Sans Bold / VL Gothic (see resolveFonts).
    FontPaths fonts;
    // The strings file; empty: the one the booth ships (StringTable::defaultFile).
    std::filesystem::path stringsFile;
    // The face oval in the camera's frame: must be the guidance's (GuidanceSettings::oval) so that the visitor
    // sees the oval the hints are about.
    FaceOval oval;
    // Where the Start (green) button is relative to the Retake (red) one, as seen by the visitor: the keep and
    // retake labels are drawn on the side of their button.
    bool startButtonOnLeft = true;
};

// Figures for the operator menu, gathered by the kiosk from the session store.
struct OperatorInfo {
    std::vector<std::pair<std::string, WallTime>> recentCodes;  // newest first (the menu shows up to 10)
    int sessionsStored = 0;
    std::uintmax_t freeBytes = 0;
    RetentionReport lastFreed;  // what the last FreeDisk did
    std::string printer;        // the printer's last news ([print] on; "" = printing off)
    bool printerProblem = false;  // ... and whether the operator has to act on it (shown in red)
    int screenRecoveries = 0;     // times the screen came back after going away (shown when not 0)
};

struct ScreenInputs {
    cv::Mat preview;                 // the camera's frame (BGR, not mirrored): guides and countdown
    cv::Mat avatar;                  // the avatar (BGR, or BGRA with coverage as alpha): attract, reveal
    // Several styles of the avatar, most important first (the first is drawn largest, in the middle); when given,
    // shown instead of `avatar`.
    std::vector<StyledAvatar> avatars;
    cv::Mat stage;                   // the tile stage (BGRA), drawn in ScreenLayout::stage under the avatars
    // Changes whenever the avatar image changes; 0: unknown (the screen is composed afresh every time). With a
    // version, a reveal whose avatar has not changed is not composed again.
    std::uint64_t avatarVersion = 0;
    cv::Mat frontPhoto, sidePhoto;   // the photos taken (BGR; may be empty): the retake question
    OperatorInfo operatorInfo;       // the operator menu
};

// Where things are on the screen (pixels), for the drawing and for tests that look at the pixels.
struct ScreenLayout {
    cv::Rect top;       // title / step label band
    cv::Rect banner;    // error banner band
    cv::Rect middle;    // avatar, code, progress
    cv::Rect bottom;    // hint, prompt, button labels
    cv::Rect leftLabel, rightLabel;  // the two button labels inside `bottom`
    cv::Rect code;      // the thanks screen's code box
    // The thanks screen when sharing is on: the QR code of the visitor's page (the largest square that fits, quiet
    // zone included) and the code box beside it (landscape) or above it (portrait).
    cv::Rect qr;
    cv::Rect codeBesideQr;
    cv::Rect progress;  // the processing screen's bar
    cv::Rect stage;     // attract and reveal: the band the tile stage fills, under the avatars
    double unit = 1.0;  // the text scale: shorter screen side / 720
};

// Not thread-safe: one renderer per drawing thread.
class ScreenRenderer {
public:
    // Opens the fonts and loads the strings; throws BoothError(BadConfig) naming a missing font or a bad strings
    // file, or a screen smaller than 320x240.
    explicit ScreenRenderer(ScreenSettings settings);
    ~ScreenRenderer();

    // Draws the screen for `model`. The image (CV_8UC3, settings().size) belongs to the renderer and stays valid
    // until the next draw().
    const cv::Mat& draw(const ScreenModel& model, const ScreenInputs& inputs);

    const ScreenSettings& settings() const { return settings_; }
    const ScreenLayout& layout() const { return layout_; }
    const StringTable& strings() const { return strings_; }
    TextRenderer& text() { return *text_; }

    // The area the avatars are drawn in on the attract or reveal screen, and each avatar's place in it when `count`
    // are shown (avatarCells; the order is the importance order of ScreenInputs::avatars).
    cv::Rect avatarArea(ScreenId screen) const;
    // Landscape: a row, the first (a quarter wider) in the middle, the second left of it, the third right, and so
    // on outwards. Portrait: the first across the top two thirds, the others in a row under it.
    static std::vector<cv::Rect> avatarCells(cv::Rect area, int count);

    // Where a point of a camera frame of size `frame` lands on the screen: the preview is mirrored (the visitor
    // sees a mirror) and scaled to fill the screen, centred, cropping what does not fit.
    cv::Point2d previewToScreen(cv::Point2d cameraPx, cv::Size frame) const;

    // Where each of `count` avatars is shown on the attract or reveal screen (the cell less its label): an avatar
    // image of min(width, height) pixels square is shown there without rescaling.
    std::vector<cv::Rect> avatarImageBoxes(ScreenId screen, int count) const;

private:
    void drawBackground();
    void drawPreview(const cv::Mat& preview, bool ovalLit, bool profile);
    void drawBanner(const ScreenModel& model);
    void drawText(const std::string& text, cv::Rect box, int pixelSize, cv::Scalar colour,
                  FontWeight weight = FontWeight::Regular, double alpha = 1.0);
    void drawButtonLabel(const std::string& text, cv::Rect box, bool startButton);
    void drawImageFitted(const cv::Mat& image, cv::Rect box, bool mirror = false);
    void drawAvatars(const ScreenInputs& in, ScreenId screen);
    int labelHeight() const { return static_cast<int>(40 * layout_.unit); }  // a style's name under its avatar
    void drawProfileOutline(cv::Rect box, bool noseRight, cv::Scalar colour, int thickness);

    void attract(const ScreenModel& m, const ScreenInputs& in);
    void guide(const ScreenModel& m, const ScreenInputs& in);
    void countdown(const ScreenModel& m, const ScreenInputs& in);
    void processing(const ScreenModel& m);
    void reveal(const ScreenInputs& in);
    void retakeChoice(const ScreenInputs& in);
    void thanks(const ScreenModel& m);
    void cameraLost(const ScreenModel& m);
    void operatorMenu(const ScreenModel& m, const ScreenInputs& in);

    const std::string& str(std::string_view key) const { return strings_.get(settings_.language, key); }

    ScreenSettings settings_;
    StringTable strings_;
    std::unique_ptr<TextRenderer> text_;
    ScreenLayout layout_;
    cv::Mat canvas_, background_, scratch_, dimmed_;
    struct BigText {
        cv::Mat text, halo;       // CV_8U coverage of the glyphs and of the halo around them
        cv::Point originOffset;   // from the baseline's left end to the masks' top-left corner
        int width = 0, ascent = 0;
    };
    std::map<std::string, BigText> bigText_;  // the countdown's numbers
    // The widest letter a session code can have (kCodeAlphabet) in this renderer's bold font at the code's size,
    // measured the first time a code is shown: the thanks screen sizes every code by it.
    int widestCodeLetterAt_ = 0;  // the pixel size it was measured at (0: not yet)
    char widestCodeLetter_ = 0;
    // The reveal without its avatar and banner (background, title, button labels: the same every frame), and what
    // the canvas holds after the last reveal drawn: its avatar version and banner.
    cv::Mat revealLayer_;
    struct RevealShown {
        std::uint64_t avatarVersion = 0;
        ScreenModel model;  // with sinceEntered 0: the reveal draws nothing that moves with time but the avatar
    };
    std::optional<RevealShown> revealShown_;
    cv::Mat outsideOval_;       // 255 outside the oval, for the last preview size
    // The thanks screen's QR code, drawn once per URL (not every frame).
    std::string qrUrl_;
    cv::Mat qrImage_;
    cv::Size outsideOvalFor_;   // the preview size outsideOval_ was made for
};

}  // namespace avatarbooth
