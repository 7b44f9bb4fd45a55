// The simulated camera on session folders written here: frame timing with an injected clock, scenes, exact
// stills, noise, faults (unplug, torn and late frames), recovery through ReopeningCamera, and clear errors for
// missing or broken photos.
#include "test_paths.h"

#include "drivers/camera/camera_factory.h"
#include "drivers/camera/sim_camera.h"
#include "fit/head/base_head.h"
#include "render/mesh_renderer.h"
#include "sim/synthetic_visitor.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <fstream>

namespace fs = std::filesystem;
using namespace avatarbooth;
using namespace std::chrono_literals;

namespace {

const cv::Vec3b kFront(10, 20, 30), kSide(200, 100, 50), kBackground(90, 90, 90), kNeutral(160, 160, 160);

// front 200x100, side 100x100 (another aspect), background 200x100, all flat colours, as PNG (lossless).
fs::path flatFolder(const std::string& name, bool withBackground = true) {
    const auto dir = test::scratchDir(name);
    cv::imwrite((dir / "front.png").string(), cv::Mat(100, 200, CV_8UC3, cv::Scalar(kFront)));
    cv::imwrite((dir / "side.png").string(), cv::Mat(100, 100, CV_8UC3, cv::Scalar(kSide)));
    if (withBackground) cv::imwrite((dir / "background.png").string(), cv::Mat(100, 200, CV_8UC3, cv::Scalar(kBackground)));
    return dir;
}

SimCameraOptions options(const fs::path& folder, int noise = 0) {
    SimCameraOptions o;
    o.folder = folder;
    o.fps = 30;
    o.previewWidth = 100;
    o.previewHeight = 80;  // the 200x100 front fits as 100x50
    o.noise = noise;
    return o;
}

struct Rig {
    std::shared_ptr<SimCameraControls> controls = std::make_shared<SimCameraControls>();
    std::shared_ptr<ManualClock> clock = std::make_shared<ManualClock>(SteadyTime{});
};

std::chrono::nanoseconds frameTime(std::uint64_t n, double fps = 30) {
    return std::chrono::nanoseconds(std::llround(static_cast<double>(n) * 1e9 / fps));
}

void writeBytes(const fs::path& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
}

// Expects SimCamera on `folder` to fail with BadInput naming `file`, with `why` in the message.
void expectBadInput(const fs::path& folder, const std::string& file, const std::string& why) {
    try {
        SimCamera camera(options(folder), nullptr, nullptr);
        FAIL() << "expected a BoothError about " << file;
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadInput);
        EXPECT_EQ(fs::path(e.where()).filename().string(), file) << e.what();
        EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(folder.string()), std::string::npos) << e.what();
    }
}

}  // namespace

TEST(CameraSim, FramesComeAtTheSetRateWithExactTimestamps) {
    Rig rig;
    SimCamera camera(options(flatFolder("camera_sim_rate")), rig.controls, rig.clock);
    for (std::uint64_t n = 0; n < 10; ++n) {
        const auto frame = camera.nextFrame(1s);
        ASSERT_TRUE(frame);
        EXPECT_EQ(frame->sequence, n);
        EXPECT_EQ(frame->timestamp, frameTime(n));
        EXPECT_EQ(rig.clock->now().time_since_epoch(), frameTime(n));  // "slept" exactly until the frame was due
    }
    EXPECT_EQ(frameTime(3), 100'000'000ns);

    auto at25 = options(flatFolder("camera_sim_rate25"));
    at25.fps = 25;
    Rig rig25;
    SimCamera slower(at25, rig25.controls, rig25.clock);
    for (std::uint64_t n = 0; n < 5; ++n) EXPECT_EQ(slower.nextFrame(1s)->timestamp, std::chrono::milliseconds(40 * n));
}

TEST(CameraSim, TimeoutBeforeTheNextFrameReturnsNothing) {
    Rig rig;
    SimCamera camera(options(flatFolder("camera_sim_timeout")), rig.controls, rig.clock);
    ASSERT_TRUE(camera.nextFrame(1s));
    EXPECT_FALSE(camera.nextFrame(10ms));
    EXPECT_EQ(rig.clock->now().time_since_epoch(), 10ms);
    const auto frame = camera.nextFrame(100ms);
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->sequence, 1u);
    EXPECT_EQ(frame->timestamp, frameTime(1));
}

TEST(CameraSim, SlowReaderLosesFramesBeyondTheQueue) {
    Rig rig;
    SimCamera camera(options(flatFolder("camera_sim_slow")), rig.controls, rig.clock);
    ASSERT_TRUE(camera.nextFrame(1s));
    rig.clock->advance(frameTime(10));  // frames 1..10 produced meanwhile; the queue holds the newest 4
    auto frame = camera.nextFrame(1s);
    EXPECT_EQ(frame->sequence, 7u);
    EXPECT_EQ(frame->timestamp, frameTime(7));
    EXPECT_EQ(camera.nextFrame(1s)->sequence, 8u);
    EXPECT_EQ(rig.clock->now().time_since_epoch(), frameTime(10));  // queued frames come without waiting
    camera.nextFrame(1s);
    camera.nextFrame(1s);
    frame = camera.nextFrame(1s);
    EXPECT_EQ(frame->sequence, 11u);
    EXPECT_EQ(rig.clock->now().time_since_epoch(), frameTime(11));
}

TEST(CameraSim, RealClockPacesFramesAtTheRate) {
    auto o = options(flatFolder("camera_sim_realtime"));
    o.fps = 100;
    SimCamera camera(o, nullptr, std::make_shared<SteadyClock>());
    const auto first = camera.nextFrame(1s);
    const auto second = camera.nextFrame(1s);
    ASSERT_TRUE(first && second);
    EXPECT_EQ(second->timestamp - first->timestamp, 10ms);
    EXPECT_EQ(second->sequence, first->sequence + 1);
    const auto now = std::chrono::steady_clock::now().time_since_epoch();
    EXPECT_GE(now, second->timestamp);  // it was not handed out before it was due
}

TEST(CameraSim, SceneDecidesThePreviewAndTheStill) {
    Rig rig;
    const auto folder = flatFolder("camera_sim_scenes");
    SimCamera camera(options(folder), rig.controls, rig.clock);
    const auto d = camera.describe();
    EXPECT_EQ(d.backend, "sim");
    EXPECT_EQ(d.device, folder.string());
    EXPECT_EQ(d.preview.width, 100);
    EXPECT_EQ(d.preview.height, 50);
    EXPECT_EQ(d.preview.fps, 30);
    EXPECT_EQ(d.still.width, 200);
    EXPECT_EQ(d.still.height, 100);

    auto frame = camera.nextFrame(1s);
    EXPECT_EQ(frame->image.size(), cv::Size(100, 50));
    EXPECT_EQ(frame->image.at<cv::Vec3b>(25, 50), kBackground);  // starts empty
    rig.controls->setScene(SimScene::Front);
    frame = camera.nextFrame(1s);
    EXPECT_EQ(frame->image.at<cv::Vec3b>(0, 0), kFront);
    EXPECT_EQ(frame->image.at<cv::Vec3b>(49, 99), kFront);
    rig.controls->setScene(SimScene::Side);
    frame = camera.nextFrame(1s);
    // The square side photo fits as 50x50 in the middle, neutral backdrop either side.
    EXPECT_EQ(frame->image.size(), cv::Size(100, 50));
    EXPECT_EQ(frame->image.at<cv::Vec3b>(25, 50), kSide);
    EXPECT_EQ(frame->image.at<cv::Vec3b>(25, 25), kSide);
    EXPECT_EQ(frame->image.at<cv::Vec3b>(25, 74), kSide);
    EXPECT_EQ(frame->image.at<cv::Vec3b>(25, 24), kNeutral);
    EXPECT_EQ(frame->image.at<cv::Vec3b>(25, 75), kNeutral);

    EXPECT_EQ(camera.captureStill().image.at<cv::Vec3b>(0, 0), kSide);
    rig.controls->setScene(SimScene::Empty);
    EXPECT_EQ(camera.captureStill().image.at<cv::Vec3b>(0, 0), kBackground);
}

TEST(CameraSim, WithoutBackgroundTheEmptyBoothIsNeutralGrey) {
    Rig rig;
    SimCamera camera(options(flatFolder("camera_sim_nobg", false)), rig.controls, rig.clock);
    EXPECT_EQ(camera.nextFrame(1s)->image.at<cv::Vec3b>(10, 10), kNeutral);
    const auto still = camera.captureStill();
    EXPECT_EQ(still.image.size(), cv::Size(200, 100));
    EXPECT_EQ(still.image.at<cv::Vec3b>(99, 199), kNeutral);
}

TEST(CameraSim, StillsAreTheFolderImagesExactly) {
    const auto dir = test::scratchDir("camera_sim_stills");
    cv::Mat front(480, 640, CV_8UC3), side(400, 300, CV_8UC3);
    cv::randu(front, 0, 256);
    cv::randu(side, 0, 256);
    cv::imwrite((dir / "front.png").string(), front);
    cv::imwrite((dir / "side.jpg").string(), side);
    const cv::Mat sideAsRead = cv::imread((dir / "side.jpg").string());
    Rig rig;
    SimCamera camera(options(dir, 2), rig.controls, rig.clock);
    rig.controls->setScene(SimScene::Front);
    auto still = camera.captureStill();
    EXPECT_EQ(still.sequence, 0u);
    EXPECT_EQ(still.image.size(), front.size());
    EXPECT_EQ(cv::norm(still.image, front, cv::NORM_INF), 0.0);  // no noise on stills
    still.image.setTo(cv::Scalar::all(0));                       // the caller owns its copy
    rig.controls->setScene(SimScene::Side);
    still = camera.captureStill();
    EXPECT_EQ(still.sequence, 1u);
    EXPECT_EQ(cv::norm(still.image, sideAsRead, cv::NORM_INF), 0.0);
    rig.controls->setScene(SimScene::Front);
    EXPECT_EQ(cv::norm(camera.captureStill().image, front, cv::NORM_INF), 0.0);
}

TEST(CameraSim, NoiseIsSlightDifferentPerFrameAndReproducible) {
    Rig rig, rig2;
    const auto folder = flatFolder("camera_sim_noise");
    SimCamera camera(options(folder, 2), rig.controls, rig.clock);
    SimCamera twin(options(folder, 2), rig2.controls, rig2.clock);
    const cv::Mat clean(50, 100, CV_8UC3, cv::Scalar(kBackground));
    const auto a = camera.nextFrame(1s)->image;
    const auto b = camera.nextFrame(1s)->image;
    EXPECT_EQ(cv::norm(a, clean, cv::NORM_INF), 2.0);
    EXPECT_EQ(cv::norm(b, clean, cv::NORM_INF), 2.0);
    EXPECT_GT(cv::norm(a, b, cv::NORM_L1), 0.0);
    const cv::Scalar mean = cv::mean(a);
    EXPECT_NEAR(mean[0], 90.0, 0.2);
    EXPECT_EQ(cv::norm(twin.nextFrame(1s)->image, a, cv::NORM_INF), 0.0);
}

TEST(CameraSim, CorruptFramesAreTornAndThenTheStreamIsClean) {
    Rig rig;
    SimCamera camera(options(flatFolder("camera_sim_corrupt")), rig.controls, rig.clock);
    rig.controls->setScene(SimScene::Front);
    ASSERT_EQ(camera.nextFrame(1s)->image.at<cv::Vec3b>(40, 10), kFront);
    rig.controls->corruptNextFrames(2);
    for (int i = 0; i < 2; ++i) {
        const auto frame = camera.nextFrame(1s);
        EXPECT_EQ(frame->image.at<cv::Vec3b>(10, 10), kFront);
        EXPECT_EQ(frame->image.at<cv::Vec3b>(25, 10), cv::Vec3b(0, 135, 0));
        EXPECT_EQ(frame->image.at<cv::Vec3b>(49, 99), cv::Vec3b(0, 135, 0));
    }
    EXPECT_EQ(camera.nextFrame(1s)->image.at<cv::Vec3b>(40, 10), kFront);
}

TEST(CameraSim, LateFrameStallsTheStreamThenTheRateResumes) {
    Rig rig;
    SimCamera camera(options(flatFolder("camera_sim_late")), rig.controls, rig.clock);
    ASSERT_TRUE(camera.nextFrame(1s));
    rig.controls->delayNextFrame(500ms);
    EXPECT_FALSE(camera.nextFrame(100ms));  // the frame due at 33 ms now comes at 533 ms
    EXPECT_EQ(rig.clock->now().time_since_epoch(), 100ms);
    auto frame = camera.nextFrame(1s);
    EXPECT_EQ(frame->sequence, 1u);
    EXPECT_EQ(frame->timestamp, frameTime(1) + 500ms);
    frame = camera.nextFrame(1s);
    EXPECT_EQ(frame->sequence, 2u);
    EXPECT_EQ(frame->timestamp, frameTime(2) + 500ms);
}

TEST(CameraSim, VanishThrowsCameraGoneAndANewCameraWorksAfterComeBack) {
    Rig rig;
    const auto folder = flatFolder("camera_sim_vanish");
    SimCamera camera(options(folder), rig.controls, rig.clock);
    ASSERT_TRUE(camera.nextFrame(1s));
    rig.controls->vanish();
    try {
        camera.nextFrame(1s);
        FAIL() << "expected CameraGoneError";
    } catch (const CameraGoneError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_EQ(std::string(e.what()), "camera sim:" + folder.string() + " disconnected (simulated unplug)");
    }
    EXPECT_THROW(camera.captureStill(), CameraGoneError);
    EXPECT_THROW(SimCamera(options(folder), rig.controls, rig.clock), CameraGoneError);
    rig.controls->comeBack();
    EXPECT_THROW(camera.nextFrame(1s), CameraGoneError);  // this one stays dead, like a closed device
    SimCamera again(options(folder), rig.controls, rig.clock);
    EXPECT_TRUE(again.nextFrame(1s));
}

TEST(CameraSim, ReopeningCameraRecoversFromVanishAndFramesResume) {
    CameraSettings settings;
    settings.backend = "sim";
    settings.simFolder = flatFolder("camera_sim_reopen").string();
    settings.simRealTime = false;
    settings.previewWidth = 100;
    settings.previewHeight = 80;
    settings.simNoise = 0;
    Rig rig;
    auto camera = openReopeningCamera(settings, {rig.controls, rig.clock});
    rig.controls->setScene(SimScene::Front);
    for (std::uint64_t n = 0; n < 5; ++n) EXPECT_EQ(camera->nextFrame(1s)->sequence, n);

    rig.controls->vanish();
    EXPECT_FALSE(camera->nextFrame(100ms));
    auto status = camera->status();
    EXPECT_FALSE(status.ok);
    EXPECT_EQ(status.message, "camera sim:" + settings.simFolder + " disconnected, retrying");
    EXPECT_THROW(camera->captureStill(), CameraGoneError);
    for (int i = 0; i < 20; ++i) EXPECT_FALSE(camera->nextFrame(100ms));  // 2 s unplugged
    EXPECT_GT(camera->status().failedReopens, 1);

    rig.controls->comeBack();
    std::optional<CameraFrame> frame;
    for (int i = 0; i < 100 && !frame; ++i) frame = camera->nextFrame(100ms);
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->sequence, 5u);
    EXPECT_EQ(frame->image.at<cv::Vec3b>(10, 10), kFront);  // the same world: still the front scene
    EXPECT_TRUE(camera->status().ok);
    EXPECT_EQ(camera->status().recoveries, 1);
    EXPECT_EQ(camera->nextFrame(1s)->sequence, 6u);
    EXPECT_EQ(cv::norm(camera->captureStill().image, cv::Mat(100, 200, CV_8UC3, cv::Scalar(kFront)), cv::NORM_INF), 0.0);
}

TEST(CameraSim, MissingOrBrokenPhotosNameTheFile) {
    auto folder = flatFolder("camera_sim_missing_front");
    fs::remove(folder / "front.png");
    expectBadInput(folder, "front.*", "no front photo");

    folder = flatFolder("camera_sim_missing_side");
    fs::remove(folder / "side.png");
    expectBadInput(folder, "side.*", "no side photo");

    folder = flatFolder("camera_sim_corrupt_side");
    fs::remove(folder / "side.png");
    writeBytes(folder / "side.jpg", "this is not a JPEG at all");
    expectBadInput(folder, "side.jpg", "is not a JPEG or PNG image");

    folder = flatFolder("camera_sim_truncated_front");
    fs::remove(folder / "front.png");
    cv::Mat photo(120, 160, CV_8UC3);
    cv::randu(photo, 0, 256);
    std::vector<unsigned char> jpeg;
    cv::imencode(".jpg", photo, jpeg);
    writeBytes(folder / "front.jpg", std::string(jpeg.begin(), jpeg.begin() + static_cast<long>(jpeg.size() / 2)));
    expectBadInput(folder, "front.jpg", "truncated JPEG");

    folder = flatFolder("camera_sim_garbled_front");
    fs::remove(folder / "front.png");
    std::string garbled(jpeg.begin(), jpeg.end());
    std::fill(garbled.begin() + 4, garbled.end() - 2, '\x11');
    writeBytes(folder / "front.jpg", garbled);
    expectBadInput(folder, "front.jpg", "damaged JPEG");

    folder = flatFolder("camera_sim_empty_background");
    writeBytes(folder / "background.png", "");
    fs::remove(folder / "background.png");
    writeBytes(folder / "background.jpg", "");
    expectBadInput(folder, "background.jpg", "is empty");

    folder = flatFolder("camera_sim_two_fronts");
    cv::imwrite((folder / "front.jpg").string(), photo);
    expectBadInput(folder, "front.jpg", "more than one front image");

    try {
        SimCamera camera(options(test::scratchDir("camera_sim_parent") / "nowhere"), nullptr, nullptr);
        FAIL() << "expected a BoothError";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadInput);
        EXPECT_NE(std::string(e.what()).find("nowhere: sim camera folder not found"), std::string::npos) << e.what();
    }
}

TEST(CameraSim, FactoryOpensTheSimAndAutoFallsBackToItWithoutDevices) {
    CameraSettings settings;
    settings.simFolder = flatFolder("camera_sim_factory").string();
    settings.simRealTime = false;
    settings.backend = "sim";
    auto camera = openReopeningCamera(settings);
    EXPECT_EQ(camera->describe().backend, "sim");
    EXPECT_EQ(camera->nextFrame(1s)->timestamp, 0ns);  // simRealTime = false: a manual clock from 0
    EXPECT_EQ(camera->nextFrame(1s)->timestamp, frameTime(1));

    settings.backend = "nonsense";
    try {
        openReopeningCamera(settings);
        FAIL() << "expected a BoothError";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_NE(std::string(e.what()).find("unknown camera backend \"nonsense\""), std::string::npos);
    }

    settings.backend = "auto";
    const auto choice = chooseCameraBackend(settings);
    if (choice.backend != "sim") GTEST_SKIP() << "this machine has a camera: " << choice.reason;
    EXPECT_EQ(choice.reason, "auto: no V4L2 or libcamera camera found, using the simulated camera");
    camera = openReopeningCamera(settings);
    EXPECT_EQ(camera->describe().backend, "sim");
    EXPECT_EQ(camera->describe().note, choice.reason);
    EXPECT_NE(camera->describe().summary().find("using the simulated camera"), std::string::npos);
}

TEST(CameraSim, ReplaysTheSyntheticVisitorFolder) {
    MeshRenderer renderer;
    SyntheticVisitorOptions o;
    o.textureSize = 512;
    const auto visitor = makeSyntheticVisitor(builtinBaseHead(), renderer, o);
    const auto folder = test::scratchDir("camera_sim_visitor") / "visitor";
    writeSyntheticVisitorFolder(visitor, folder);

    CameraSettings settings;
    settings.backend = "sim";
    settings.simFolder = folder.string();
    settings.simRealTime = false;
    auto controls = std::make_shared<SimCameraControls>();
    auto camera = openReopeningCamera(settings, {controls, nullptr});
    const auto d = camera->describe();
    EXPECT_EQ(d.preview.width, 972);  // fits in 1280x720 already: never enlarged
    EXPECT_EQ(d.preview.height, 720);
    controls->setScene(SimScene::Front);
    EXPECT_EQ(cv::norm(camera->captureStill().image, cv::imread((folder / "front.jpg").string()), cv::NORM_INF), 0.0);
    controls->setScene(SimScene::Side);
    EXPECT_EQ(cv::norm(camera->captureStill().image, cv::imread((folder / "side.jpg").string()), cv::NORM_INF), 0.0);
    controls->setScene(SimScene::Empty);
    EXPECT_EQ(cv::norm(camera->captureStill().image, cv::imread((folder / "background.png").string()), cv::NORM_INF), 0.0);
    // The preview of the front scene is the front photo plus at most 2 grey levels of noise.
    controls->setScene(SimScene::Front);
    EXPECT_LE(cv::norm(camera->nextFrame(1s)->image, cv::imread((folder / "front.jpg").string()), cv::NORM_INF), 2.0);
}

// The booth makes the default synthetic visitor's folder once (a render of about 2 s that a restarted booth must not
// repeat before its attract screen), and again only when a file is missing (an earlier run killed while writing it).
TEST(CameraSim, SyntheticVisitorFolderIsMadeOnceAndRemadeWhenIncomplete) {
    const auto folder = test::scratchDir("camera_sim_ensure") / "synthetic-visitor";
    EXPECT_EQ(ensureSyntheticVisitorFolder(folder), folder);
    for (const char* name : {"front.jpg", "side.jpg", "background.png", "truth/head.glb", "truth/landmarks.json"})
        ASSERT_TRUE(fs::is_regular_file(folder / name)) << name;
    const auto made = fs::last_write_time(folder / "front.jpg");
    ensureSyntheticVisitorFolder(folder);
    EXPECT_EQ(fs::last_write_time(folder / "front.jpg"), made) << "a complete folder was written again";

    fs::remove(folder / "truth" / "landmarks.json");  // written last: without it the folder is not whole
    fs::last_write_time(folder / "front.jpg", made - 1h);
    ensureSyntheticVisitorFolder(folder);
    EXPECT_TRUE(fs::is_regular_file(folder / "truth" / "landmarks.json"));
    EXPECT_GT(fs::last_write_time(folder / "front.jpg"), made - 1h);
}
