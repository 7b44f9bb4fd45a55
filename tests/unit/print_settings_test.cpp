// [print] and [sound] in booth.toml ([print] off and [sound] on by default, every key read, mistakes named by file,
// line and key) and how a CUPS queue's state reads to the operator (print/cups_queue.h): problems, and their words.
#include "config/booth_config.h"
#include "config_error_of.h"
#include "print/cups_queue.h"

#include <gtest/gtest.h>

using namespace avatarbooth;
using avatarbooth::test::errorOf;

TEST(PrintConfig, OffByDefaultAndReadFromTheFile) {
    const BoothConfig defaults;
    EXPECT_FALSE(defaults.print.enabled);
    EXPECT_DOUBLE_EQ(defaults.print.widthMm, 100.0);
    EXPECT_DOUBLE_EQ(defaults.print.heightMm, 148.0);
    EXPECT_EQ(defaults.print.dpi, 300);
    EXPECT_FALSE(defaults.print.frontPhoto);
    const BoothConfig c = parseBoothConfig("[print]\nenabled = true\nqueue = \"Canon_SELPHY\"\nwidth_mm = 89\n"
                                           "height_mm = 127\ndpi = 600\nmedia = \"Postcard\"\nfront_photo = true\n"
                                           "title = \"Open day\"\ncopies = 2\n",
                                           "booth.toml");
    EXPECT_TRUE(c.print.enabled);
    EXPECT_EQ(c.print.queue, "Canon_SELPHY");
    EXPECT_DOUBLE_EQ(c.print.widthMm, 89.0);
    EXPECT_DOUBLE_EQ(c.print.heightMm, 127.0);
    EXPECT_EQ(c.print.dpi, 600);
    EXPECT_EQ(c.print.media, "Postcard");
    EXPECT_TRUE(c.print.frontPhoto);
    EXPECT_EQ(c.print.title, "Open day");
    EXPECT_EQ(c.print.copies, 2);
}

TEST(PrintConfig, MistakesNameFileLineAndKey) {
    EXPECT_EQ(errorOf("[print]\nenabled = 1\n"), "booth.toml:2: print.enabled: expected true or false");
    EXPECT_EQ(errorOf("[print]\n\nqueue = \"my printer\"\n"),
              "booth.toml:3: print.queue: \"my printer\" is not a CUPS queue name (no spaces, /, # or quotes)");
    EXPECT_EQ(errorOf("[print]\ncopies = 0\n"), "booth.toml:2: print.copies: must be between 1 and 10, got 0");
    EXPECT_EQ(errorOf("[print]\npaper = \"A6\"\n"), "booth.toml:2: print.paper: unknown key (see the reference booth.toml for the keys there are)");
}

TEST(PrintQueueState, ProblemsAreWhatAnOperatorMustActOn) {
    QueueState idle;
    idle.queue = "photo";
    idle.accepting = true;
    EXPECT_FALSE(idle.problem());
    EXPECT_EQ(idle.describe(), "idle, accepting jobs");

    QueueState empty = idle;
    empty.reasons = {"media-empty-error"};
    EXPECT_TRUE(empty.problem());
    EXPECT_EQ(empty.describe(), "idle, accepting jobs: out of paper (media-empty-error)");
    QueueState needed = idle;
    needed.reasons = {"media-needed-warning"};
    EXPECT_TRUE(needed.problem());

    QueueState paused = idle;
    paused.stopped = true;
    paused.reasons = {"paused"};
    paused.message = "out of cards";
    EXPECT_TRUE(paused.problem());
    EXPECT_EQ(paused.describe(), "stopped, accepting jobs (paused) \"out of cards\"");

    QueueState rejecting = idle;
    rejecting.accepting = false;
    EXPECT_TRUE(rejecting.problem());

    QueueState warning = idle;
    warning.reasons = {"marker-supply-low-warning"};  // ink low: worth a look, not a stop
    EXPECT_FALSE(warning.problem());

    QueueState missing;
    missing.error = "no print queue \"x\" on the CUPS server";
    EXPECT_FALSE(missing.found());
    EXPECT_TRUE(missing.problem());
    EXPECT_EQ(missing.describe(), missing.error);
}

TEST(PrintJobState, FinishedStatesAndWords) {
    JobState j;
    j.state = JobState::State::Held;
    j.reasons = {"job-hold-until-specified"};
    EXPECT_FALSE(j.finished());
    EXPECT_EQ(j.describe(), "held (job-hold-until-specified)");
    j.state = JobState::State::Aborted;
    j.reasons = {"aborted-by-system"};
    EXPECT_TRUE(j.finished());
    EXPECT_EQ(j.describe(), "failed (aborted) (aborted-by-system)");
    j.state = JobState::State::Completed;
    j.reasons = {"job-completed-successfully"};
    EXPECT_EQ(j.describe(), "printed");
}

TEST(SoundConfig, OnByDefaultAndReadFromTheFile) {
    const BoothConfig defaults;
    EXPECT_TRUE(defaults.sound.enabled);
    EXPECT_EQ(defaults.sound.volume, 80);
    EXPECT_EQ(defaults.sound.device, "default");
    const BoothConfig c = parseBoothConfig("[sound]\nenabled = false\nvolume = 30\ndevice = \"hw:1\"\n", "booth.toml");
    EXPECT_FALSE(c.sound.enabled);
    EXPECT_EQ(c.sound.volume, 30);
    EXPECT_EQ(c.sound.device, "hw:1");
    EXPECT_EQ(errorOf("[sound]\nvolume = 101\n"), "booth.toml:2: sound.volume: must be between 0 and 100, got 101");
}
