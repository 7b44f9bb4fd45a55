// ReopeningCamera with a scripted camera and a manual clock: losing the camera, the back-off schedule, the
// status the screen shows, and frames resuming with continuous sequence numbers.
#include "drivers/camera/reopening_camera.h"

#include <gtest/gtest.h>

#include <vector>

using namespace avatarbooth;
using namespace std::chrono_literals;

namespace {

// The "hardware": whether the camera is plugged in, and what happened to it.
struct FakeWorld {
    bool present = true;
    bool misconfigured = false;
    std::vector<std::chrono::nanoseconds> openTimes;  // when each open was attempted
    int starts = 0;
    std::shared_ptr<ManualClock> clock = std::make_shared<ManualClock>(SteadyTime{});
};

// Frames every 10 ms from its own sequence 0; throws CameraGoneError once the world unplugs it.
class FakeCamera : public Camera {
public:
    explicit FakeCamera(FakeWorld& world) : world_(world) {}
    void start() override {
        check();
        ++world_.starts;
    }
    std::optional<CameraFrame> nextFrame(std::chrono::milliseconds) override {
        check();
        world_.clock->advance(10ms);
        return CameraFrame{cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(1)), next_++, world_.clock->now().time_since_epoch()};
    }
    CameraFrame captureStill() override {
        check();
        return CameraFrame{cv::Mat(2, 2, CV_8UC3, cv::Scalar::all(2)), 0, world_.clock->now().time_since_epoch()};
    }
    void stop() override {}
    CameraDescription describe() const override { return {"fake", "/dev/fake", "fake camera", {}, {}, ""}; }

private:
    void check() const {
        if (!world_.present) throw CameraGoneError("/dev/fake", "ENODEV");
    }
    FakeWorld& world_;
    std::uint64_t next_ = 0;
};

std::unique_ptr<ReopeningCamera> makeCamera(FakeWorld& world) {
    auto open = [&world]() -> std::unique_ptr<Camera> {
        world.openTimes.push_back(world.clock->now().time_since_epoch());
        if (world.misconfigured) throw BoothError(ErrorKind::BadConfig, "camera.device", "not a camera path");
        if (!world.present) throw BoothError(ErrorKind::Device, "/dev/fake", "no such camera device");
        return std::make_unique<FakeCamera>(world);
    };
    return std::make_unique<ReopeningCamera>(open, "/dev/fake", ReopenPolicy{500ms, 4s}, world.clock);
}

}  // namespace

TEST(CameraReopening, PassesFramesThroughWhileTheCameraIsThere) {
    FakeWorld world;
    auto camera = makeCamera(world);
    for (std::uint64_t i = 0; i < 3; ++i) {
        const auto frame = camera->nextFrame(100ms);
        ASSERT_TRUE(frame);
        EXPECT_EQ(frame->sequence, i);
    }
    EXPECT_TRUE(camera->status().ok);
    EXPECT_EQ(camera->status().message, "");
    EXPECT_EQ(world.openTimes.size(), 1u);
    EXPECT_EQ(camera->describe().device, "/dev/fake");
}

TEST(CameraReopening, RetriesWithDoublingDelaysAndResumesWhenTheCameraComesBack) {
    FakeWorld world;
    auto camera = makeCamera(world);
    for (int i = 0; i < 5; ++i) ASSERT_TRUE(camera->nextFrame(100ms));  // sequences 0..4, clock at 50 ms
    ASSERT_EQ(world.clock->now().time_since_epoch(), 50ms);

    world.present = false;
    EXPECT_FALSE(camera->nextFrame(100ms));  // lost at 50 ms; first retry due at 550 ms
    auto status = camera->status();
    EXPECT_FALSE(status.ok);
    EXPECT_EQ(status.message, "camera /dev/fake disconnected, retrying");
    EXPECT_EQ(status.lastError, "camera /dev/fake disconnected (ENODEV)");
    EXPECT_EQ(camera->current(), nullptr);
    EXPECT_EQ(camera->describe().note, "camera /dev/fake disconnected, retrying");
    EXPECT_EQ(world.clock->now().time_since_epoch(), 150ms);  // waited out its timeout

    // Keep asking for frames for 20 s of camera time: retries at 0.55, 1.55, 3.55, 7.55, 11.55, 15.55, 19.55 s
    // (delays 0.5, 1, 2, 4, then capped at 4).
    while (world.clock->now().time_since_epoch() < 20s) EXPECT_FALSE(camera->nextFrame(250ms));
    const std::vector<std::chrono::nanoseconds> expected{0ms, 550ms, 1550ms, 3550ms, 7550ms, 11550ms, 15550ms, 19550ms};
    EXPECT_EQ(world.openTimes, expected);
    EXPECT_EQ(camera->status().failedReopens, 7);
    EXPECT_EQ(camera->status().lastError, "/dev/fake: no such camera device");

    world.present = true;
    const int startsBefore = world.starts;
    std::optional<CameraFrame> frame;
    while (!frame) frame = camera->nextFrame(250ms);
    EXPECT_EQ(world.openTimes.back(), 23550ms);
    EXPECT_EQ(frame->sequence, 5u);  // continues after the last frame before the loss
    EXPECT_EQ(world.starts, startsBefore + 1);  // the stream was restarted on the new camera
    status = camera->status();
    EXPECT_TRUE(status.ok);
    EXPECT_EQ(status.message, "");
    EXPECT_EQ(status.recoveries, 1);
    EXPECT_EQ(camera->nextFrame(100ms)->sequence, 6u);
}

TEST(CameraReopening, BackOffStartsAgainAfterARecovery) {
    FakeWorld world;
    auto camera = makeCamera(world);
    ASSERT_TRUE(camera->nextFrame(100ms));
    for (int round = 0; round < 2; ++round) {
        world.present = false;
        world.openTimes.clear();
        const auto lostAt = world.clock->now().time_since_epoch();
        while (world.clock->now().time_since_epoch() < lostAt + 2s) camera->nextFrame(100ms);
        world.present = true;
        while (!camera->nextFrame(100ms)) {
        }
        ASSERT_GE(world.openTimes.size(), 2u);
        EXPECT_EQ(world.openTimes[0], lostAt + 500ms) << "round " << round;
        EXPECT_EQ(world.openTimes[1], lostAt + 1500ms) << "round " << round;
    }
    EXPECT_EQ(camera->status().recoveries, 2);
}

TEST(CameraReopening, StartsLostWhenTheFirstOpenFindsNoDevice) {
    FakeWorld world;
    world.present = false;
    auto camera = makeCamera(world);
    EXPECT_FALSE(camera->status().ok);
    EXPECT_EQ(camera->status().message, "camera /dev/fake not found, retrying");
    EXPECT_FALSE(camera->nextFrame(100ms));
    world.present = true;
    std::optional<CameraFrame> frame;
    while (!frame) frame = camera->nextFrame(1s);
    EXPECT_EQ(frame->sequence, 0u);
    EXPECT_EQ(world.openTimes.back(), 500ms);
    EXPECT_TRUE(camera->status().ok);
}

TEST(CameraReopening, AMisconfiguredCameraFailsAtOnce) {
    FakeWorld world;
    world.misconfigured = true;
    try {
        makeCamera(world);
        FAIL() << "expected a BoothError";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
    }
}

TEST(CameraReopening, StillWhileLostTriesAtOnceThenReportsTheCameraGone) {
    FakeWorld world;
    auto camera = makeCamera(world);
    ASSERT_TRUE(camera->nextFrame(100ms));
    world.present = false;
    EXPECT_THROW(camera->captureStill(), CameraGoneError);  // goes away during the still
    EXPECT_FALSE(camera->status().ok);
    const auto opensBefore = world.openTimes.size();
    try {
        camera->captureStill();
        FAIL() << "expected CameraGoneError";
    } catch (const CameraGoneError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_EQ(std::string(e.what()), "camera /dev/fake disconnected (/dev/fake: no such camera device)");
    }
    EXPECT_EQ(world.openTimes.size(), opensBefore + 1);  // tried once, without waiting for the back-off
    world.present = true;
    EXPECT_EQ(camera->captureStill().image.cols, 2);
    EXPECT_TRUE(camera->status().ok);
}
