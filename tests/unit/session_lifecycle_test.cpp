// The session folder's life from lists of events: keep before and after the write ends, retakes during the write,
// a failed write kept again, crash leftovers and retention, the style extras (the toon strip) after a keep.
// Commands are compared as their describe() strings, in order.
#include "booth/session_lifecycle.h"

#include "fit/fit_pipeline.h"
#include "reveal/character/character_outputs.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

using namespace avatarbooth;
using namespace avatarbooth::session;

namespace {

using Names = std::vector<std::string>;

// A lifecycle whose pending folders are p1, p2, ... in order.
class Sessions {
public:
    explicit Sessions(bool styleExtras = true)
        : lifecycle([this] { return std::filesystem::path("/s/.pending") / ("p" + std::to_string(++folders)); },
                    styleExtras) {}

    Names send(const Event& e) {
        last.clear();
        Names out;
        for (const auto& c : lifecycle.handle(e)) {
            out.push_back(describe(c));
            last.push_back(c);
        }
        return out;
    }
    // A fit of `job` that worked, and its character made: the write is asked for.
    Names fittedAndCharacter(std::uint64_t job) {
        EXPECT_EQ(send(FitSubmitted{job}), Names{});
        EXPECT_EQ(send(Fitted{job, outcome}), Names{});
        return send(CharacterMade{job, character});
    }
    Names written(std::uint64_t job, const std::string& folder, std::optional<std::string> error = std::nullopt) {
        return send(FolderWritten{job, "/s/.pending/" + folder, std::move(error), FlowTime{}});
    }
    Names kept(std::uint64_t job, const std::string& folder, const std::string& code) {
        return send(KeepDone{job, "/s/.pending/" + folder, code, "/s/" + code, "", FlowTime{}});
    }

    int folders = 0;
    std::shared_ptr<const FitOutcome> outcome = std::make_shared<FitOutcome>();
    std::shared_ptr<const CharacterOutputs> character = std::make_shared<CharacterOutputs>();
    SessionLifecycle lifecycle;
    std::vector<Command> last;
};

TEST(SessionLifecycle, KeptDuringTheWriteIsKeptOnceWrittenThenTheToonStripFollows) {
    Sessions s;
    EXPECT_EQ(s.fittedAndCharacter(1), Names{"WriteFolder(1 -> p1)"});
    const auto& write = std::get<WriteFolder>(s.last.at(0));
    EXPECT_EQ(write.outcome, s.outcome);
    EXPECT_EQ(write.character, s.character);  // the character made for it goes into the folder
    EXPECT_EQ(s.send(KeepAsked{FlowTime{}}), Names{});  // still writing: kept when written
    EXPECT_TRUE(s.lifecycle.keptSessionInFlight() == false);  // (its character was already made)
    EXPECT_EQ(s.written(1, "p1"), Names{"KeepFolder(1, p1)"});
    EXPECT_EQ(s.kept(1, "p1", "AB3K7Z"), Names{"TellFlow(saved)"});
    EXPECT_EQ(std::get<SessionSaved>(std::get<TellFlow>(s.last.at(0)).event).code, "AB3K7Z");
    EXPECT_TRUE(s.lifecycle.styleExtrasAwaited());  // the toon is still being drawn
    EXPECT_EQ(s.send(StylesSettled{}), Names{"WriteStyleExtras(AB3K7Z)"});
    EXPECT_FALSE(s.lifecycle.styleExtrasAwaited());
    EXPECT_EQ(s.send(StylesSettled{}), Names{});
}

TEST(SessionLifecycle, KeptAfterTheWriteIsKeptAtOnceWithTheToonStripWhenAlreadyDrawn) {
    Sessions s;
    EXPECT_EQ(s.fittedAndCharacter(1), Names{"WriteFolder(1 -> p1)"});
    EXPECT_EQ(s.written(1, "p1"), Names{});  // held for the visitor's choice
    EXPECT_EQ(s.send(StylesSettled{}), Names{});
    EXPECT_EQ(s.send(KeepAsked{FlowTime{}}), Names{"KeepFolder(1, p1)"});
    EXPECT_EQ(s.kept(1, "p1", "CODE22"), (Names{"TellFlow(saved)", "WriteStyleExtras(CODE22)"}));
}

TEST(SessionLifecycle, KeptBeforeTheCharacterIsWrittenThenKept) {
    Sessions s;
    EXPECT_EQ(s.send(FitSubmitted{1}), Names{});
    EXPECT_EQ(s.send(Fitted{1, s.outcome}), Names{});
    EXPECT_EQ(s.send(KeepAsked{FlowTime{}}), Names{});
    EXPECT_TRUE(s.lifecycle.keptSessionInFlight());  // the run's end waits for it
    EXPECT_EQ(s.send(CharacterMade{1, nullptr}), Names{"WriteFolder(1 -> p1)"});
    EXPECT_EQ(std::get<WriteFolder>(s.last.at(0)).character, nullptr);  // no character: none in the folder
    EXPECT_FALSE(s.lifecycle.keptSessionInFlight());
    EXPECT_EQ(s.written(1, "p1"), Names{"KeepFolder(1, p1)"});
}

TEST(SessionLifecycle, ARetakeDuringTheWriteRemovesTheEarlierFolderWhenItsWriteEnds) {
    Sessions s;
    EXPECT_EQ(s.fittedAndCharacter(1), Names{"WriteFolder(1 -> p1)"});
    EXPECT_EQ(s.send(FitSubmitted{2}), Names{});  // p1 is still being written: removed when its write reports
    EXPECT_EQ(s.written(1, "p1"), Names{"DiscardFolder(p1)"});
    EXPECT_EQ(s.send(Fitted{2, s.outcome}), Names{});
    EXPECT_EQ(s.send(CharacterMade{2, s.character}), Names{"WriteFolder(2 -> p2)"});
    EXPECT_EQ(s.written(2, "p2"), Names{});
    EXPECT_EQ(s.send(KeepAsked{FlowTime{}}), Names{"KeepFolder(2, p2)"});
}

TEST(SessionLifecycle, ARetakeAfterTheWriteRemovesTheEarlierFolderAtOnce) {
    Sessions s;
    EXPECT_EQ(s.fittedAndCharacter(1), Names{"WriteFolder(1 -> p1)"});
    EXPECT_EQ(s.written(1, "p1"), Names{});
    EXPECT_EQ(s.send(FitSubmitted{2}), Names{"DiscardFolder(p1)"});
}

TEST(SessionLifecycle, ADiscardBeforeTheCharacterWritesNothing) {
    Sessions s;
    EXPECT_EQ(s.send(FitSubmitted{1}), Names{});
    EXPECT_EQ(s.send(Fitted{1, s.outcome}), Names{});
    EXPECT_EQ(s.send(DiscardAsked{}), Names{});
    EXPECT_EQ(s.send(CharacterMade{1, s.character}), Names{});  // never written
    EXPECT_EQ(s.send(KeepAsked{FlowTime{}}), Names{"TellFlow(save failed)"});
    EXPECT_EQ(std::get<SessionSaveFailed>(std::get<TellFlow>(s.last.at(0)).event).detail, "no fitted avatar to keep");
}

TEST(SessionLifecycle, AFailedWriteIsWrittenAgainForTheKeep) {
    Sessions s;
    EXPECT_EQ(s.fittedAndCharacter(1), Names{"WriteFolder(1 -> p1)"});
    EXPECT_EQ(s.written(1, "p1", "avatar.glb: no space left on device"), Names{"DiscardFolder(p1)"});
    EXPECT_EQ(s.send(KeepAsked{FlowTime{}}), Names{"WriteFolder(1 -> p2)"});
    EXPECT_EQ(std::get<WriteFolder>(s.last.at(0)).character, s.character);
    EXPECT_EQ(s.written(1, "p2"), Names{"KeepFolder(1, p2)"});
    // Failing again: the visitor is told, nothing stays.
    Sessions t;
    t.fittedAndCharacter(1);
    t.written(1, "p1", "disk full");
    t.send(KeepAsked{FlowTime{}});
    EXPECT_EQ(t.written(1, "p2", "disk still full"), (Names{"DiscardFolder(p2)", "TellFlow(save failed)"}));
    EXPECT_EQ(std::get<SessionSaveFailed>(std::get<TellFlow>(t.last.at(1)).event).detail, "disk still full");
}

TEST(SessionLifecycle, AKeepTheStoreRefusesIsDiscardedAndTold) {
    Sessions s;
    s.fittedAndCharacter(1);
    s.written(1, "p1");
    EXPECT_EQ(s.send(KeepAsked{FlowTime{}}), Names{"KeepFolder(1, p1)"});
    EXPECT_EQ(s.send(KeepDone{1, "/s/.pending/p1", "", "", "session.json: read-only file system", FlowTime{}}),
              (Names{"DiscardFolder(p1)", "TellFlow(save failed)"}));
    EXPECT_FALSE(s.lifecycle.styleExtrasAwaited());
}

TEST(SessionLifecycle, TheNextVisitorBeforeTheToonIsDrawnLeavesTheKeptSessionWithoutItsStrip) {
    Sessions s;
    s.fittedAndCharacter(1);
    s.written(1, "p1");
    s.send(KeepAsked{FlowTime{}});
    EXPECT_EQ(s.kept(1, "p1", "FIRST2"), Names{"TellFlow(saved)"});
    EXPECT_TRUE(s.lifecycle.styleExtrasAwaited());
    EXPECT_EQ(s.send(FitSubmitted{2}), Names{});
    EXPECT_EQ(s.send(Fitted{2, s.outcome}), Names{});  // the styles now show visitor 2
    EXPECT_FALSE(s.lifecycle.styleExtrasAwaited());
    EXPECT_EQ(s.send(StylesSettled{}), Names{});  // visitor 2's toon: not written into visitor 1's session
}

TEST(SessionLifecycle, WithoutAStyleWithExtrasAKeepWritesNone) {
    Sessions s(/*styleExtras=*/false);
    s.fittedAndCharacter(1);
    s.written(1, "p1");
    s.send(KeepAsked{FlowTime{}});
    EXPECT_EQ(s.kept(1, "p1", "NOTOON"), Names{"TellFlow(saved)"});
    EXPECT_FALSE(s.lifecycle.styleExtrasAwaited());
}

TEST(SessionLifecycle, CrashLeftoversGoAtStartAndRetentionRunsEveryTenMinutes) {
    Sessions s;
    const auto t0 = std::chrono::steady_clock::time_point{} + std::chrono::hours(1);
    EXPECT_EQ(s.send(Started{t0}), (Names{"RemoveLeftovers", "ApplyRetention"}));
    EXPECT_EQ(s.send(TimePassed{t0 + std::chrono::minutes(9)}), Names{});
    EXPECT_EQ(s.send(TimePassed{t0 + std::chrono::minutes(10)}), Names{"ApplyRetention"});
    EXPECT_EQ(s.send(TimePassed{t0 + std::chrono::minutes(15)}), Names{});
    EXPECT_EQ(s.send(TimePassed{t0 + std::chrono::minutes(20)}), Names{"ApplyRetention"});
    EXPECT_EQ(s.send(FreeDiskAsked{}), (Names{"ApplyRetention", "RemoveLeftovers"}));
}

TEST(SessionLifecycle, AWriteNobodyWaitsForIsDiscarded) {
    Sessions s;
    s.fittedAndCharacter(1);
    EXPECT_EQ(s.send(DiscardAsked{}), Names{});  // the visitor walked away during the write
    EXPECT_EQ(s.written(1, "p1"), Names{"DiscardFolder(p1)"});
}

}  // namespace
