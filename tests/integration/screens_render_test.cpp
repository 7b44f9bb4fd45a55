// Every screen drawn in both languages, landscape and portrait, checked on its pixels (text where it belongs, the
// preview mirrored, the code's glyphs, the avatar, the labels by their buttons), written as PNGs into
// build/.../tests/work/screens/ for a person to look at, and timed at 1280x720 (printed, not asserted).
#include "booth/screens/screens.h"

#include "common/error.h"

#include "fit/head/base_head.h"
#include "render/mesh_renderer.h"
#include "sim/synthetic_visitor.h"
#include "test_paths.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

using namespace avatarbooth;

namespace {

struct Visitor {
    SyntheticVisitor v;
    cv::Mat avatar;  // BGRA, the visitor's head at three quarters, coverage as alpha
};

const Visitor& visitor() {
    static const Visitor vis = [] {
        MeshRenderer renderer;
        SyntheticVisitorOptions o;
        o.seed = 2;
        o.textureSize = 512;
        o.sideNoseImageRight = false;  // as the booth takes it: the visitor turned to their right
        Visitor out{makeSyntheticVisitor(builtinBaseHead(), renderer, o), {}};
        renderer.upload(out.v.truthMesh, out.v.texture);
        const RenderResult r = renderer.render(RenderCamera::orthographic({500, 0, 866}, {0, -20, 0}, {0, 1, 0}, 0.6,
                                                                          512, 512));
        std::vector<cv::Mat> ch;
        cv::split(r.bgr, ch);
        ch.push_back(r.mask);
        cv::merge(ch, out.avatar);
        return out;
    }();
    return vis;
}

// A 640x480 preview frame, as the camera streams it.
cv::Mat previewOf(const cv::Mat& photo) {
    cv::Mat out;
    cv::resize(photo, out, {640, 480}, 0, 0, cv::INTER_AREA);
    return out;
}

ScreenInputs inputsFor(const ScreenModel& m) {
    ScreenInputs in;
    const Visitor& vis = visitor();
    if (m.id == ScreenId::SideGuide || (m.id == ScreenId::Countdown && m.photo == Photo::Side))
        in.preview = previewOf(vis.v.side);
    else
        in.preview = previewOf(vis.v.front);
    in.avatar = vis.avatar;
    in.frontPhoto = vis.v.front;
    in.sidePhoto = vis.v.side;
    const auto now = std::chrono::system_clock::now();
    in.operatorInfo.recentCodes = {{"AB3K7Z", now}, {"Q7M2XP", now - std::chrono::minutes(7)},
                                   {"HN4W9C", now - std::chrono::minutes(19)}};
    in.operatorInfo.sessionsStored = 3;
    in.operatorInfo.freeBytes = 12'300'000'000;
    in.operatorInfo.lastFreed = {4, 1, 8'400'000};
    return in;
}

struct Case {
    std::string name;
    ScreenModel model;
};

// One model per screen (and per notable variant).
std::vector<Case> allScreens() {
    std::vector<Case> out;
    auto add = [&](std::string name, auto&& edit) {
        ScreenModel m;
        edit(m);
        out.push_back({std::move(name), m});
    };
    add("attract", [](ScreenModel& m) { m.id = ScreenId::Attract; });
    add("attract_camera_lost", [](ScreenModel& m) {
        m.id = ScreenId::Attract;
        m.cameraAvailable = false;
        m.banner = BannerKind::CameraLost;
    });
    add("front_guide", [](ScreenModel& m) {
        m.id = ScreenId::FrontGuide;
        m.hint = Hint::StepCloser;
    });
    add("front_guide_ready", [](ScreenModel& m) {
        m.id = ScreenId::FrontGuide;
        m.hint = Hint::HoldStill;
    });
    add("front_guide_fit_failed", [](ScreenModel& m) {
        m.id = ScreenId::FrontGuide;
        m.hint = Hint::NoFace;
        m.banner = BannerKind::FitFailed;
        m.fitFailure = FitFailure::NoFace;
    });
    add("countdown", [](ScreenModel& m) {
        m.id = ScreenId::Countdown;
        m.countdown = 3;
    });
    add("capture_flash", [](ScreenModel& m) { m.id = ScreenId::CaptureFlash; });
    add("side_guide", [](ScreenModel& m) {
        m.id = ScreenId::SideGuide;
        m.photo = Photo::Side;
        m.hint = Hint::TurnMore;
    });
    add("side_guide_not_profile", [](ScreenModel& m) {
        m.id = ScreenId::SideGuide;
        m.photo = Photo::Side;
        m.hint = Hint::TurnRight;
        m.banner = BannerKind::FitFailed;
        m.fitFailure = FitFailure::NotProfile;
    });
    add("side_guide_turned_past", [](ScreenModel& m) {
        m.id = ScreenId::SideGuide;
        m.photo = Photo::Side;
        m.hint = Hint::TurnBack;
        m.banner = BannerKind::FitFailed;
        m.fitFailure = FitFailure::TurnBack;
    });
    add("side_guide_face_hidden", [](ScreenModel& m) {
        m.id = ScreenId::SideGuide;
        m.photo = Photo::Side;
        m.hint = Hint::FaceHidden;
        m.banner = BannerKind::FitFailed;
        m.fitFailure = FitFailure::FaceHidden;
    });
    add("side_countdown", [](ScreenModel& m) {
        m.id = ScreenId::Countdown;
        m.photo = Photo::Side;
        m.countdown = 1;
    });
    add("processing", [](ScreenModel& m) {
        m.id = ScreenId::Processing;
        m.progress = 0.55;
        m.fitStep = FitStep::HeadFit;
        m.sinceEntered = Millis(1700);
    });
    add("reveal", [](ScreenModel& m) { m.id = ScreenId::Reveal; });
    add("retake_choice", [](ScreenModel& m) { m.id = ScreenId::RetakeChoice; });
    add("thanks", [](ScreenModel& m) {
        m.id = ScreenId::Thanks;
        m.code = "AB3K7Z";
    });
    add("thanks_saving", [](ScreenModel& m) { m.id = ScreenId::Thanks; });
    add("thanks_save_failed", [](ScreenModel& m) {
        m.id = ScreenId::Thanks;
        m.banner = BannerKind::SaveFailed;
    });
    add("camera_lost", [](ScreenModel& m) {
        m.id = ScreenId::CameraLost;
        m.cameraAvailable = false;
        m.banner = BannerKind::CameraLost;
        m.detail = "/dev/video0: No such device";
    });
    add("operator_menu", [](ScreenModel& m) {
        m.id = ScreenId::OperatorMenu;
        m.menuItem = OperatorItem::FreeDisk;
    });
    add("operator_codes", [](ScreenModel& m) {
        m.id = ScreenId::OperatorMenu;
        m.menuPage = OperatorPage::LastCodes;
    });
    add("operator_free_disk", [](ScreenModel& m) {
        m.id = ScreenId::OperatorMenu;
        m.menuPage = OperatorPage::FreeDisk;
    });
    return out;
}

ScreenRenderer& renderer(Language language, cv::Size size) {
    static std::map<std::pair<int, std::pair<int, int>>, std::unique_ptr<ScreenRenderer>> cache;
    auto& r = cache[{static_cast<int>(language), {size.width, size.height}}];
    if (!r) {
        ScreenSettings s;
        s.language = language;
        s.size = size;
        r = std::make_unique<ScreenRenderer>(s);
    }
    return *r;
}

// Pixels within `tolerance` (max over channels) of a colour.
int pixelsNear(const cv::Mat& img, cv::Rect r, cv::Scalar colour, int tolerance = 40) {
    r &= cv::Rect(0, 0, img.cols, img.rows);
    cv::Mat lo, hi, mask;
    const cv::Scalar t(tolerance, tolerance, tolerance);
    cv::inRange(img(r), colour - t, colour + t, mask);
    return cv::countNonZero(mask);
}

const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kAccent(40, 175, 255);
const cv::Scalar kInk(40, 30, 25);
const cv::Scalar kStartGreen(90, 190, 60);
const cv::Scalar kRetakeRed(70, 70, 225);

}  // namespace

class Screens : public ::testing::TestWithParam<std::tuple<Language, cv::Size>> {};

TEST_P(Screens, EveryScreenRendersWithTextWhereItBelongs) {
    const auto [language, size] = GetParam();
    ScreenRenderer& r = renderer(language, size);
    const ScreenLayout& L = r.layout();
    const auto dir = std::filesystem::path(AVATARBOOTH_TEST_WORK_DIR) / "screens";
    std::filesystem::create_directories(dir);
    for (const Case& c : allScreens()) {
        SCOPED_TRACE(c.name);
        const cv::Mat img = r.draw(c.model, inputsFor(c.model)).clone();
        ASSERT_EQ(img.size(), size);
        ASSERT_EQ(img.type(), CV_8UC3);
        cv::imwrite((dir / cv::format("%s_%dx%d_%s.png", languageCode(language), size.width, size.height,
                                      c.name.c_str()))
                        .string(),
                    img);
        const int minText = static_cast<int>(150 * L.unit * L.unit);
        switch (c.model.id) {
            case ScreenId::Attract:
                EXPECT_GT(pixelsNear(img, L.top, kAccent), minText) << "title";
                EXPECT_GT(pixelsNear(img, L.bottom, kWhite, 70), minText) << "press the button";
                EXPECT_GT(pixelsNear(img, L.bottom, kStartGreen, 10), minText) << "the button's colour";
                break;
            case ScreenId::FrontGuide:
            case ScreenId::SideGuide: {
                const cv::Scalar hintColour = c.model.hint == Hint::HoldStill ? cv::Scalar(110, 230, 90) : kWhite;
                EXPECT_GT(pixelsNear(img, L.bottom, hintColour, 30), minText) << "hint";
                EXPECT_GT(pixelsNear(img, L.top, cv::Scalar(235, 235, 235), 30), minText) << "step label";
                break;
            }
            case ScreenId::Countdown: {
                const cv::Rect centre(size.width / 4, size.height / 4, size.width / 2, size.height / 2);
                EXPECT_GT(pixelsNear(img, centre, kWhite, 30), minText * 10) << "the big number";
                break;
            }
            case ScreenId::CaptureFlash: EXPECT_EQ(pixelsNear(img, {0, 0, size.width, size.height}, kWhite, 0), size.area()); break;
            case ScreenId::Processing:
                EXPECT_GT(pixelsNear(img, L.top, kAccent), minText) << "title";
                EXPECT_GT(pixelsNear(img, L.progress, kAccent, 10), L.progress.area() / 3) << "progress bar";
                EXPECT_LT(pixelsNear(img, L.progress, kAccent, 10), L.progress.area() * 2 / 3) << "progress bar";
                break;
            case ScreenId::Reveal:
            case ScreenId::RetakeChoice:
                EXPECT_GT(pixelsNear(img, L.top, kAccent), minText) << "title";
                EXPECT_GT(pixelsNear(img, L.leftLabel, kWhite, 30), minText) << "left label";
                EXPECT_GT(pixelsNear(img, L.rightLabel, kWhite, 30), minText) << "right label";
                EXPECT_GT(pixelsNear(img, L.leftLabel, kStartGreen, 10), minText) << "Start's colour on the left";
                EXPECT_GT(pixelsNear(img, L.rightLabel, kRetakeRed, 10), minText) << "Retake's colour on the right";
                break;
            case ScreenId::Thanks:
                EXPECT_GT(pixelsNear(img, L.top, kAccent), minText) << "title";
                if (c.model.banner != BannerKind::SaveFailed) {
                    EXPECT_GT(pixelsNear(img, L.code, kInk, 30), minText) << "code or saving";
                }
                break;
            case ScreenId::CameraLost:
                EXPECT_GT(pixelsNear(img, {0, size.height / 2, size.width, size.height / 2}, kWhite, 30), minText);
                break;
            case ScreenId::OperatorMenu:
                EXPECT_GT(pixelsNear(img, {0, 0, size.width, size.height / 6}, kAccent), minText) << "title";
                EXPECT_GT(pixelsNear(img, {0, size.height / 6, size.width, size.height / 2}, cv::Scalar(235, 235, 235),
                                     30),
                          minText)
                    << "items or codes";
                break;
        }
        if (c.model.banner != BannerKind::None && c.model.id != ScreenId::CameraLost) {
            const cv::Scalar band =
                c.model.banner == BannerKind::CameraLost ? cv::Scalar(0, 120, 215) : cv::Scalar(45, 45, 185);
            EXPECT_GT(pixelsNear(img, L.banner, band, 30), L.banner.area() / 3) << "banner band";
            EXPECT_GT(pixelsNear(img, L.banner, kWhite, 30), minText) << "banner text";
        }
    }
}

INSTANTIATE_TEST_SUITE_P(BothLanguagesBothOrientations, Screens,
                         ::testing::Combine(::testing::Values(Language::English, Language::Japanese),
                                            ::testing::Values(cv::Size(1280, 720), cv::Size(720, 1280))),
                         [](const auto& p) {
                             return std::string(languageCode(std::get<0>(p.param))) + "_" +
                                    std::to_string(std::get<1>(p.param).width) + "x" +
                                    std::to_string(std::get<1>(p.param).height);
                         });

TEST(ScreensPixels, PreviewIsMirrored) {
    ScreenRenderer& r = renderer(Language::English, {1280, 720});
    // A grey frame with a green square left of the frame's centre, inside the oval.
    cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(90, 90, 90));
    cv::rectangle(frame, cv::Rect(230, 220, 40, 40), cv::Scalar(0, 255, 0), cv::FILLED);
    ScreenModel m;
    m.id = ScreenId::FrontGuide;
    ScreenInputs in;
    in.preview = frame;
    const cv::Mat img = r.draw(m, in);
    // Scale 2 (cover 1280x720 with 640x480), mirrored about the centre: camera (250, 240) -> screen (780, 360).
    EXPECT_EQ(r.previewToScreen({250, 240}, frame.size()), cv::Point2d(780, 360));
    EXPECT_EQ(img.at<cv::Vec3b>(360, 780), cv::Vec3b(0, 255, 0));
    EXPECT_EQ(img.at<cv::Vec3b>(360, 500), cv::Vec3b(90, 90, 90));  // where it would be without the mirror
    // Outside the oval the preview is dimmed to 40 %.
    EXPECT_EQ(img.at<cv::Vec3b>(200, 40), cv::Vec3b(36, 36, 36));
}

TEST(ScreensPixels, CodeGlyphsAreDrawn) {
    ScreenRenderer& r = renderer(Language::English, {1280, 720});
    ScreenModel m;
    m.id = ScreenId::Thanks;
    m.code = "AB3K7Z";
    const cv::Mat a = r.draw(m, {}).clone();
    // Each character is one blob of dark ink in the light code box (inside its rounded corners): six, side by side.
    const int corner = 30;
    const cv::Rect inner(r.layout().code.x + corner, r.layout().code.y + corner, r.layout().code.width - 2 * corner,
                         r.layout().code.height - 2 * corner);
    cv::Mat ink, labels, stats, centroids;
    cv::inRange(a(inner), cv::Scalar(0, 0, 0), cv::Scalar(120, 120, 120), ink);
    const int n = cv::connectedComponentsWithStats(ink, labels, stats, centroids);
    std::vector<double> xs;
    for (int i = 1; i < n; ++i)
        if (stats.at<int>(i, cv::CC_STAT_AREA) > 100) xs.push_back(centroids.at<double>(i, 0));
    ASSERT_EQ(xs.size(), 6u);
    std::sort(xs.begin(), xs.end());
    for (std::size_t i = 1; i < xs.size(); ++i) EXPECT_GT(xs[i] - xs[i - 1], 50.0);
    // Another code draws other pixels in the box; no code ("saving") fewer ink pixels than the code.
    m.code = "234567";
    const cv::Mat b = r.draw(m, {}).clone();
    EXPECT_GT(cv::norm(a(r.layout().code), b(r.layout().code), cv::NORM_L1), 1e5);
    m.code.clear();
    const cv::Mat c = r.draw(m, {}).clone();
    cv::Mat inkSaving;
    cv::inRange(c(inner), cv::Scalar(0, 0, 0), cv::Scalar(120, 120, 120), inkSaving);
    EXPECT_GT(cv::countNonZero(inkSaving), 0);
    EXPECT_NE(cv::countNonZero(inkSaving), cv::countNonZero(ink));
}

TEST(ScreensPixels, EveryCodeShowsAtOneSizeAndTheWidestFits) {
    // Both languages: Japanese text draws its Latin letters with the Japanese font, whose widest letter may differ.
    for (const Language language : {Language::English, Language::Japanese})
    for (const cv::Size screen : {cv::Size(1280, 720), cv::Size(800, 480), cv::Size(480, 800)}) {
        SCOPED_TRACE(std::string(languageCode(language)) + " " + std::to_string(screen.width) + "x" +
                     std::to_string(screen.height));
        ScreenRenderer& r = renderer(language, screen);
        // Inside the code's light box: below and above its rounded corners (radius 28 units; the page around is
        // dark), and 12 units in from its ends (half the margin the code keeps).
        const double u = r.layout().unit;
        const int corner = static_cast<int>(std::ceil(28 * u)) + 2, end = static_cast<int>(std::ceil(12 * u));
        const cv::Rect box(r.layout().code.x + end, r.layout().code.y + corner, r.layout().code.width - 2 * end,
                           r.layout().code.height - 2 * corner);
        // The ink of the code's letters: its bounding box, and how many letters (blobs) it has.
        const auto inkOf = [&](const std::string& code) {
            ScreenModel m;
            m.id = ScreenId::Thanks;
            m.code = code;
            cv::Mat ink, labels, stats, centroids;
            cv::inRange(r.draw(m, {})(box), cv::Scalar(0, 0, 0), cv::Scalar(120, 120, 120), ink);
            int letters = 0;
            for (int i = 1, n = cv::connectedComponentsWithStats(ink, labels, stats, centroids); i < n; ++i)
                letters += stats.at<int>(i, cv::CC_STAT_AREA) > 20;
            return std::make_pair(cv::boundingRect(ink), letters);
        };
        const auto [wide, wideLetters] = inkOf("WWWWWW");
        const auto [narrow, narrowLetters] = inkOf("EEEEEE");
        const auto [digits, digitLetters] = inkOf("234567");
        EXPECT_EQ(wideLetters, 6) << screen;
        EXPECT_EQ(narrowLetters, 6) << screen;
        EXPECT_EQ(digitLetters, 6) << screen;
        // Capitals of one size: the same height, whatever the code's width.
        EXPECT_EQ(wide.height, narrow.height) << screen;
        EXPECT_NEAR(digits.height, narrow.height, 2) << screen;  // digits are about as tall as capitals
        // Every code inside the box, not touching its ends: each letter of the alphabet six times over.
        cv::Rect widest;
        for (char c : kCodeAlphabet) {
            const cv::Rect ink = inkOf(std::string(6, c)).first;
            EXPECT_GT(ink.x, 0) << c;
            EXPECT_LT(ink.br().x, box.width) << c;
            if (ink.width > widest.width) widest = ink;
        }
        // As big as the box allows: the widest code fills its width, or the letters are a good part of its height.
        EXPECT_TRUE(widest.width > box.width * 8 / 10 || widest.height > r.layout().code.height / 4) << widest;
    }
}

// The side guide's arrow points where the visitor should turn: their right (the mirrored preview's right) while
// turning, back the other way when turned past the profile or no face shows. The arrowhead is the arrow's wider end.
TEST(ScreensPixels, SideArrowPointsTheWayToTurn) {
    ScreenRenderer& r = renderer(Language::English, {1280, 720});
    ScreenModel m;
    m.id = ScreenId::SideGuide;
    m.photo = Photo::Side;
    ScreenInputs in;
    in.preview = previewOf(visitor().v.side);
    const cv::Rect middle = r.layout().middle;
    const auto headOnRight = [&](Hint hint) {
        m.hint = hint;
        const cv::Mat img = r.draw(m, in);
        cv::Mat accent;
        cv::inRange(img(middle), kAccent - cv::Scalar::all(40), kAccent + cv::Scalar::all(40), accent);
        const cv::Rect box = cv::boundingRect(accent);
        EXPECT_GT(box.width, 40) << toString(hint) << ": no arrow";
        // Column counts of the arrow's pixels: the head's end has the most.
        const int third = box.width / 3;
        const int left = cv::countNonZero(accent(cv::Rect(box.x, box.y, third, box.height)));
        const int right = cv::countNonZero(accent(cv::Rect(box.br().x - third, box.y, third, box.height)));
        return right > left;
    };
    EXPECT_TRUE(headOnRight(Hint::TurnRight));
    EXPECT_TRUE(headOnRight(Hint::TurnMore));
    EXPECT_FALSE(headOnRight(Hint::TurnBack));
    EXPECT_FALSE(headOnRight(Hint::FaceHidden));
}

TEST(ScreensPixels, HintTextFollowsTheHint) {
    ScreenRenderer& r = renderer(Language::English, {1280, 720});
    ScreenModel m;
    m.id = ScreenId::FrontGuide;
    ScreenInputs in;
    in.preview = previewOf(visitor().v.front);
    m.hint = Hint::StepCloser;
    const cv::Mat a = r.draw(m, in).clone();
    m.hint = Hint::StepBack;
    const cv::Mat b = r.draw(m, in).clone();
    const cv::Rect hintArea = r.layout().bottom;
    EXPECT_GT(cv::norm(a(hintArea), b(hintArea), cv::NORM_L1), 1e5);
    // Above the hint band the two screens are the same pixels.
    const cv::Rect above(0, 0, 1280, hintArea.y);
    EXPECT_EQ(cv::norm(a(above), b(above), cv::NORM_L1), 0.0);
}

TEST(ScreensPixels, RevealShowsTheAvatarAndSwapsLabelsWithTheButtons) {
    ScreenModel m;
    m.id = ScreenId::Reveal;
    // A plain magenta avatar: its pixels are easy to find.
    ScreenInputs in;
    in.avatar = cv::Mat(400, 300, CV_8UC4, cv::Scalar(255, 0, 255, 255));
    ScreenRenderer& r = renderer(Language::English, {1280, 720});
    const cv::Mat img = r.draw(m, in).clone();
    EXPECT_GT(pixelsNear(img, r.layout().middle, cv::Scalar(255, 0, 255), 0), 100000);
    ScreenSettings s;
    s.startButtonOnLeft = false;
    ScreenRenderer swapped(s);
    const cv::Mat sw = swapped.draw(m, in).clone();
    EXPECT_GT(pixelsNear(sw, swapped.layout().rightLabel, kStartGreen, 10), 500);
    EXPECT_GT(pixelsNear(sw, swapped.layout().leftLabel, kRetakeRed, 10), 500);
    EXPECT_EQ(pixelsNear(sw, swapped.layout().leftLabel, kStartGreen, 10), 0);
}

// The printer's news on the operator menu (issue 23's card): none while printing is off, grey while all is well,
// red when the operator has to act (out of paper, stopped), in the status lines under the menu.
TEST(ScreensPixels, OperatorMenuShowsThePrintersNewsRedWhenItIsAProblem) {
    ScreenRenderer& r = renderer(Language::English, {1280, 720});
    ScreenModel m;
    m.id = ScreenId::OperatorMenu;
    m.menuPage = OperatorPage::Menu;
    ScreenInputs in;
    const cv::Mat off = r.draw(m, in).clone();
    in.operatorInfo.printer = "queue photo: idle, accepting jobs";
    const cv::Mat fine = r.draw(m, in).clone();
    in.operatorInfo.printer = "queue photo: stopped, accepting jobs: out of paper (media-empty-error)";
    in.operatorInfo.printerProblem = true;
    const cv::Mat problem = r.draw(m, in).clone();
    const auto red = [](const cv::Mat& screen) {
        cv::Mat mask;
        cv::inRange(screen, cv::Scalar(40, 40, 180), cv::Scalar(110, 110, 255), mask);
        return cv::countNonZero(mask);
    };
    EXPECT_GT(cv::norm(off, fine, cv::NORM_L1), 1e4) << "the printer's line is drawn";
    EXPECT_LT(red(fine), 50);
    EXPECT_GT(red(problem), 500) << "a problem is drawn in red";
}

// A screen that came back after going dark (ReopeningDisplay's recoveries) is counted on the operator menu, under
// the printer's line, and the five status lines stay clear of the help line at the bottom.
TEST(ScreensPixels, OperatorMenuCountsScreenRecoveriesAboveTheHelpLine) {
    ScreenRenderer& r = renderer(Language::English, {1280, 720});
    ScreenModel m;
    m.id = ScreenId::OperatorMenu;
    m.menuPage = OperatorPage::Menu;
    ScreenInputs in;
    in.operatorInfo.printer = "queue photo: idle, accepting jobs";
    const cv::Mat before = r.draw(m, in).clone();
    in.operatorInfo.screenRecoveries = 2;
    const cv::Mat counted = r.draw(m, in).clone();
    cv::Mat diff;
    cv::absdiff(before, counted, diff);
    cv::Mat changed;
    cv::cvtColor(diff, changed, cv::COLOR_BGR2GRAY);
    EXPECT_GT(cv::countNonZero(changed > 0), 500) << "the screen's line is drawn";
    // Nothing moved into the help line's band (the bottom 80 px at 1280x720, where it is drawn).
    const cv::Rect help(0, 720 - 80, 1280, 80);
    EXPECT_EQ(cv::countNonZero(changed(help) > 0), 0) << "the status lines run into the help line";
    // Every status line's pixels stay above it.
    cv::Mat text;
    cv::inRange(counted, cv::Scalar(100, 100, 100), cv::Scalar(255, 255, 255), text);
    const cv::Rect gap(0, 720 - 80 - 4, 1280, 4);
    EXPECT_EQ(cv::countNonZero(text(gap)), 0) << "a status line reaches the help line's band";
}

TEST(ScreensPixels, AvatarAlphaIsComposited) {
    ScreenModel m;
    m.id = ScreenId::Reveal;
    ScreenInputs in;
    in.avatar = cv::Mat(400, 400, CV_8UC4, cv::Scalar(255, 0, 255, 0));  // fully transparent
    cv::circle(in.avatar, {200, 200}, 100, cv::Scalar(255, 0, 255, 255), cv::FILLED);
    ScreenRenderer& r = renderer(Language::English, {1280, 720});
    const cv::Mat img = r.draw(m, in);
    const int magenta = pixelsNear(img, r.layout().middle, cv::Scalar(255, 0, 255), 0);
    // The avatar is scaled to the middle's height: a 400 px square to about 459 px, the disc to about pi 115^2.
    const double scale = std::min(1280.0, static_cast<double>(r.layout().middle.br().y - r.layout().top.br().y)) / 400.0;
    EXPECT_NEAR(magenta, CV_PI * 100 * 100 * scale * scale, 0.05 * CV_PI * 100 * 100 * scale * scale);
}

TEST(ScreensPixels, BadScreenSizeIsAConfigError) {
    ScreenSettings s;
    s.size = {100, 100};
    EXPECT_THROW(ScreenRenderer r(s), BoothError);
}

TEST(ScreensTiming, DrawTimePerScreenAt1280x720IsPrinted) {
    for (Language language : {Language::English, Language::Japanese}) {
        ScreenRenderer& r = renderer(language, {1280, 720});
        std::string line;
        for (const Case& c : allScreens()) {
            const ScreenInputs in = inputsFor(c.model);
            r.draw(c.model, in);  // warm the glyph cache
            std::vector<double> ms;
            for (int i = 0; i < 15; ++i) {
                const auto t0 = std::chrono::steady_clock::now();
                r.draw(c.model, in);
                ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            }
            std::sort(ms.begin(), ms.end());
            line += cv::format(" %s %.1f", c.name.c_str(), ms[ms.size() / 2]);
        }
        std::printf("draw time at 1280x720 (%s), median of 15, ms:%s\n", languageCode(language), line.c_str());
    }
    SUCCEED();
}
