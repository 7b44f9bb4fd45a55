// Integration tests of the reveal's styles: the stage view (R(theta) sweep, one render per angle), the character and
// toon renderers through RevealStyles on the synthetic visitor, the toon strip kept, and the screens' layout of them.
#include "reveal/character/character_head.h"
#include "reveal/character/character_outputs.h"
#include "fit/fit_pipeline.h"
#include "common/error.h"
#include "fit/face/silhouette.h"
#include "fit/head/base_head.h"
#include "booth/screens/screens.h"
#include "reveal/styles/reveal_styles.h"
#include "render/mesh_renderer.h"
#include "sim/synthetic_visitor.h"
#include "reveal/stage/stage_view.h"
#include "test_paths.h"
#include "reveal/toon/toon_billboard.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <fstream>
#include <mutex>
#include <thread>

namespace avatarbooth {
namespace {

using namespace std::chrono_literals;

double alphaCoverage(const cv::Mat& bgra) {
    if (bgra.empty() || bgra.channels() != 4) return 0.0;
    cv::Mat alpha;
    cv::extractChannel(bgra, alpha, 3);
    return static_cast<double>(cv::countNonZero(alpha > 127)) / static_cast<double>(alpha.total());
}

// Share of the covered pixels that are the stage's grass green (green well above red and blue, whatever the light).
double greenShare(const cv::Mat& bgra) {
    int green = 0, covered = 0;
    for (int y = 0; y < bgra.rows; ++y)
        for (int x = 0; x < bgra.cols; ++x) {
            const cv::Vec4b p = bgra.at<cv::Vec4b>(y, x);
            if (p[3] < 128) continue;
            ++covered;
            if (p[1] > p[2] + 30 && p[1] > p[0] + 30) ++green;
        }
    return covered ? static_cast<double>(green) / covered : 0.0;
}

TEST(StageView, SweepHoldsAtTheTopDownLookThenEasesToTheLowViewAndBack) {
    EXPECT_DOUBLE_EQ(stage::sweepElevation(0.0, 16.0, 12.0), 45.0);
    EXPECT_DOUBLE_EQ(stage::sweepElevation(3.9, 16.0, 12.0), 45.0);
    EXPECT_NEAR(stage::sweepElevation(6.0, 16.0, 12.0), 28.5, 1e-9);  // half-way down, eased
    EXPECT_DOUBLE_EQ(stage::sweepElevation(9.0, 16.0, 12.0), 12.0);
    EXPECT_NEAR(stage::sweepElevation(14.0, 16.0, 12.0), 28.5, 1e-9);
    EXPECT_DOUBLE_EQ(stage::sweepElevation(16.0, 16.0, 12.0), 45.0);  // periodic
    // Smooth: no step bigger than the eased curve's steepest slope over a frame (1.5 x 33 deg / 4 s / 30 fps).
    double last = stage::sweepElevation(0.0, 16.0, 12.0);
    for (double t = 1.0 / 30; t < 32.0; t += 1.0 / 30) {
        const double e = stage::sweepElevation(t, 16.0, 12.0);
        EXPECT_LT(std::abs(e - last), 1.5 * 33.0 / 4.0 / 30.0 + 1e-9) << t;
        last = e;
    }
}

TEST(StageView, RendersTheShippedMapOncePerAngleWithItsTileColours) {
    const stage::TileMap map = stage::loadTileMap(stage::defaultStageMapFile());
    const cv::Size size(1280, 288);
    // The shipped 13x9 map, three times across a 1280x288 band (the landscape screen's).
    ASSERT_EQ(stage::copiesToFill(map, 1280.0 / 288.0), 3);
    const stage::TileMap wide = stage::repeatAcross(map, 3);
    ASSERT_EQ(wide.width, 39);
    EXPECT_EQ(wide.at(13 + 3, 0), map.at(3, 0));
    EXPECT_EQ(wide.edgeRight(26 + 8, 1), map.edgeRight(8, 1));
    stage::StageView view(stage::buildStage(wide));
    const cv::Mat top = view.render(45.0, size).clone();
    ASSERT_EQ(top.type(), CV_8UC4);
    ASSERT_EQ(top.size(), size);
    // Scaled to fit: the stage fills a good part of its band, and green (top faces) is the main colour.
    const double coverage = alphaCoverage(top);
    EXPECT_GT(coverage, 0.2);
    EXPECT_LT(coverage, 0.95);
    const double greenTop = greenShare(top);
    EXPECT_GT(greenTop, 0.3);
    EXPECT_EQ(view.renders(), 1);
    // The same angle (to a quarter of a degree) reuses the image.
    view.render(45.1, size);
    EXPECT_EQ(view.renders(), 1);
    const cv::Mat low = view.render(12.0, size).clone();
    EXPECT_EQ(view.renders(), 2);
    // The low view sees the tops foreshortened and the fronts (brown) more: less green.
    EXPECT_LT(greenShare(low), greenTop - 0.05);
    const std::filesystem::path dir = test::scratchDir("reveal_styles_stage");  // pictures to look at
    cv::imwrite((dir / "stage_45.png").string(), top);
    cv::imwrite((dir / "stage_12.png").string(), low);
}

TEST(StageView, TopDownLookStretchesTheStageByR45) {
    // A flat 4x4 slab one tile high, seen at 45 degrees: R(45) = sqrt(2) stretches it along the view's vertical, so
    // its image is taller (relative to its width) than without the blend, where the top is foreshortened by cos 45.
    const stage::Stage slab = stage::buildStage(stage::parseTileMap("gggg\ngggg\ngggg\ngggg\nbbbb\n"));
    stage::StageView view(slab);
    const cv::Mat blended = view.render(45.0, {400, 600});
    cv::Mat alpha;
    cv::extractChannel(blended, alpha, 3);
    const cv::Rect box = cv::boundingRect(alpha > 127);
    // Without the blend: top 4 tiles x cos45 + front 1 tile x sin45 = 3.54 tiles over 4 wide (0.88); with it,
    // the diagonal span grows by sqrt(2): 5 tiles over 4 wide (1.25).
    EXPECT_NEAR(static_cast<double>(box.height) / box.width, 1.25, 0.06);
}

struct Visitor {
    SyntheticVisitor v;
    cv::Mat frontMask, sideMask;
};

// The styles' work for a visitor, run on a thread of its own as the kiosk's style worker does; what it posts is
// run by drain() on the test's thread (the screen's, in the kiosk).
class StyleWorkRunner {
public:
    explicit StyleWorkRunner(std::vector<StyleWork> work)
        : thread_([this, work = std::move(work)] {
              const StylePost post = [this](std::function<void()> f) {
                  std::lock_guard lock(mutex_);
                  posted_.push_back(std::move(f));
              };
              for (const auto& w : work) w(post);
          }) {}
    ~StyleWorkRunner() { thread_.join(); }
    void drain() {
        std::vector<std::function<void()>> ready;
        {
            std::lock_guard lock(mutex_);
            ready.swap(posted_);
        }
        for (auto& f : ready) f();
    }

private:
    std::mutex mutex_;
    std::vector<std::function<void()>> posted_;
    std::thread thread_;
};

// Until the styles have settled (their work done and handed over), at most `limit`.
void settle(RevealStyles& styles, StyleWorkRunner& runner, std::chrono::milliseconds limit) {
    for (auto waited = 0ms; waited < limit && !styles.settled(); waited += 20ms) {
        std::this_thread::sleep_for(20ms);
        runner.drain();
    }
}

// A fit as the pipeline hands it over: the visitor's photos, masks, true landmarks and head with its texture.
FitOutcome fitOf(const Visitor& visitor) {
    FitOutcome fit;
    fit.front = visitor.v.front;
    fit.frontMask = visitor.frontMask;
    fit.side = visitor.v.side;
    fit.sideMask = visitor.sideMask;
    fit.sideNoseImageRight = SyntheticVisitorOptions{}.sideNoseImageRight;
    for (int k = 0; k < 68; ++k) fit.frontLandmarks.points[static_cast<std::size_t>(k)] = visitor.v.frontLandmarks.at(cv::format("ibug_%02d", k));
    fit.sideLandmarks = visitor.v.sideLandmarks;
    fit.fit.mesh = visitor.v.truthMesh;
    fit.texture.texture = visitor.v.texture;
    return fit;
}

const Visitor& syntheticVisitor() {
    static const Visitor visitor = [] {
        MeshRenderer renderer;
        SyntheticVisitorOptions options;
        options.textureSize = 512;
        Visitor out{makeSyntheticVisitor(builtinBaseHead(), renderer, options), {}, {}};
        out.frontMask = segmentPerson(out.v.front, out.v.background);
        out.sideMask = segmentPerson(out.v.side, out.v.background);
        return out;
    }();
    return visitor;
}

TEST(RevealStyles, CharacterToonAndStageOnTheRevealThenTheStripIsKept) {
    const Visitor& visitor = syntheticVisitor();
    RevealSettings reveal;  // photo, character, toon
    reveal.toonStripFrames = 5;
    StageSettings stageSettings;
    RevealStyles styles(reveal, stageSettings, AnimationSettings{}, builtinBaseHead());

    // Before any visitor: the photo style and the character are the base head (untextured, painted), no toon.
    const cv::Size band(1280, 288);
    const std::vector<int> sizes{480, 480, 480};
    StyleImages in;
    styles.fill(in, /*reveal=*/false, 0ms, sizes, band);
    ASSERT_EQ(in.avatars.size(), 2u);
    EXPECT_EQ(in.avatars[0].style, "photo");
    EXPECT_EQ(in.avatars[0].image.size(), cv::Size(480, 480));
    EXPECT_GT(alphaCoverage(in.avatars[0].image), 0.15);
    EXPECT_TRUE(styles.photoShown());
    EXPECT_EQ(in.avatars[1].style, "character");
    const double baseCharacter = alphaCoverage(in.avatars[1].image);
    EXPECT_GT(baseCharacter, 0.15);
    EXPECT_LT(baseCharacter, 0.8);
    EXPECT_EQ(in.stage.size(), band / 2);  // half resolution, scaled up by the screen
    EXPECT_GT(alphaCoverage(in.stage), 0.2);

    // A visitor: a character made by the pipeline's code, their toon drawn in the background.
    const BaseHead& base = builtinBaseHead();
    const CharacterProportions average = measureHead(base.mesh, base, base.earHoleCentre).proportions;
    CharacterOutputs character;
    character.head = makeCharacterHead(base, average, CharacterSettings{});
    StyleWorkRunner runner(styles.visitor(fitOf(visitor)));

    // At once: the character's place is there, empty, until the kiosk hands over the visitor's character (never
    // the previous one's); the toon's place is there, empty, while it is drawn; the reveal is not complete yet.
    std::uint64_t version = styles.version();
    styles.fill(in, /*reveal=*/true, 0ms, sizes, band);
    ASSERT_EQ(in.avatars.size(), 3u);
    EXPECT_TRUE(in.avatars[1].image.empty());
    EXPECT_FALSE(styles.complete());
    EXPECT_NE(styles.version(), version);  // a style's image went
    styles.fill(in, /*reveal=*/false, 0ms, sizes, band);
    EXPECT_EQ(in.avatars.size(), 1u);  // attract: no empty places (the photo style shows the visitor's head)
    styles.visitorCharacter(&character);
    version = styles.version();
    styles.fill(in, /*reveal=*/true, 0ms, sizes, band);
    ASSERT_EQ(in.avatars.size(), 3u);
    EXPECT_GT(alphaCoverage(in.avatars[1].image), 0.15);
    EXPECT_NE(styles.version(), version);
    const bool drawnAlready = !in.avatars[2].image.empty();
    EXPECT_EQ(styles.complete(), drawnAlready);
    settle(styles, runner, 30s);
    ASSERT_TRUE(styles.settled());

    // Every style has its image at several moments of the turn; the toon covers a head's worth of its image.
    for (const auto since : {0ms, 1500ms, 3000ms}) {
        styles.fill(in, /*reveal=*/true, since, sizes, band);
        ASSERT_EQ(in.avatars.size(), 3u);
        EXPECT_TRUE(styles.complete());
        EXPECT_EQ(in.avatars[2].style, "toon");
        const double toon = alphaCoverage(in.avatars[2].image);
        EXPECT_GT(toon, 0.15) << since.count();
        EXPECT_LT(toon, 0.8) << since.count();
        EXPECT_GT(alphaCoverage(in.avatars[1].image), 0.15);
    }
    const std::filesystem::path dir = test::scratchDir("reveal_styles");
    cv::imwrite((dir / "toon.png").string(), in.avatars[2].image);
    cv::imwrite((dir / "character.png").string(), in.avatars[1].image);

    // A held frame reuses the images (no new render).
    const StyleFigures before = styles.figures();
    styles.fill(in, true, 3000ms, sizes, band);
    const StyleFigures after = styles.figures();
    EXPECT_EQ(after.characterRenders, before.characterRenders);
    EXPECT_EQ(after.toonRenders, before.toonRenders);
    EXPECT_EQ(after.stageRenders, before.stageRenders);
    const std::uint64_t held = styles.version();
    styles.fill(in, true, 3000ms, sizes, band);
    EXPECT_EQ(styles.version(), held);  // nothing changed: the screen need not compose the reveal again
    std::printf("per render (medians, this machine): character %.1f ms, toon %.1f ms, stage %.1f ms; toon drawn in %.2f s\n",
                after.characterMs, after.toonMs, after.stageMs, after.toonBuildSeconds);

    // Kept: the strip goes into the session folder.
    const std::filesystem::path session = dir / "session";
    std::filesystem::create_directories(session);
    ASSERT_TRUE(styles.writeInto(session));
    for (int i = 0; i < 5; ++i) {
        const cv::Mat frame = cv::imread((session / "toon" / cv::format("turntable_%03d.png", i)).string());
        ASSERT_FALSE(frame.empty()) << i;
        EXPECT_EQ(frame.size(), cv::Size(400, 440));
    }
    EXPECT_FALSE(std::filesystem::exists(session / "toon" / "turntable_005.png"));
}

TEST(RevealStyles, AToonThatCannotBeDrawnSettlesWithoutAPlace) {
    RevealSettings reveal;
    reveal.styles = {AvatarStyle::Photo, AvatarStyle::Toon};
    StageSettings noStage;
    noStage.enabled = false;
    RevealStyles styles(reveal, noStage, AnimationSettings{}, builtinBaseHead());
    FitOutcome fit;
    fit.front = cv::Mat(100, 100, CV_8UC3, cv::Scalar::all(128));
    fit.frontMask = cv::Mat::zeros(100, 100, CV_8U);  // no head: toonFromPhotos refuses
    fit.side = fit.front;
    fit.sideMask = fit.frontMask;
    fit.fit.mesh = builtinBaseHead().mesh;
    fit.texture.texture = cv::Mat(8, 8, CV_8UC3, cv::Scalar::all(128));
    StyleWorkRunner runner(styles.visitor(fit));
    settle(styles, runner, 4s);
    ASSERT_TRUE(styles.settled());
    StyleImages in;
    styles.fill(in, true, 0ms, {64, 64}, cv::Size());
    ASSERT_EQ(in.avatars.size(), 1u);
    EXPECT_EQ(in.avatars[0].style, "photo");
    EXPECT_TRUE(in.stage.empty());
    EXPECT_FALSE(styles.writeInto(test::scratchDir("reveal_styles_nothing")));
}

TEST(RevealStyles, ABrokenStageMapIsAConfigErrorWithLineAndColumn) {
    const std::filesystem::path map = test::scratchDir("reveal_styles_map") / "broken.map";
    {
        std::ofstream(map) << "ggg\ngxg\n";
    }
    StageSettings s;
    s.map = map;
    try {
        RevealStyles styles(RevealSettings{}, s, AnimationSettings{}, builtinBaseHead());
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_EQ(e.where(), map.string() + ":2:2");
    }
}

TEST(RevealLayout, FirstStyleLargestInTheMiddleThenLeftThenRight) {
    const cv::Rect area(0, 94, 1280, 482);
    const auto cells = ScreenRenderer::avatarCells(area, 3);
    ASSERT_EQ(cells.size(), 3u);
    EXPECT_GT(cells[0].width, cells[1].width);
    EXPECT_EQ(cells[1].width, cells[2].width);
    EXPECT_LT(cells[1].x, cells[0].x);
    EXPECT_LT(cells[0].x, cells[2].x);
    EXPECT_EQ(cells[1].x, 0);
    EXPECT_EQ(cells[2].br().x, 1280);
    EXPECT_EQ(cells[1].br().x, cells[0].x);  // no gaps, no overlaps
    EXPECT_EQ(cells[0].br().x, cells[2].x);
    // Portrait: the first across the top, the others below.
    const auto tall = ScreenRenderer::avatarCells(cv::Rect(0, 200, 720, 900), 3);
    ASSERT_EQ(tall.size(), 3u);
    EXPECT_EQ(tall[0].width, 720);
    EXPECT_EQ(tall[1].y, tall[0].br().y);
    EXPECT_EQ(tall[1].br().x, tall[2].x);
    EXPECT_EQ(ScreenRenderer::avatarCells(area, 1), std::vector<cv::Rect>{area});
}

}  // namespace
}  // namespace avatarbooth
