// The life of a visitor's session folder, as plain logic beside VisitorFlow: fitted -> (its character made) ->
// written in the background -> kept under a code (the visitor pressed keep, before or after the write ended) or
// discarded (retake, walked away); a kept session's style extras (the toon's strip) follow when drawn; leftovers of
// a crash and the retention rules at start-up and every few minutes. Events in, commands out: it never touches a
// file, a thread or a clock, so every path is a unit test of a command sequence (session_lifecycle_test.cpp).
#pragma once

#include "booth/flow_types.h"

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace avatarbooth {

struct FitOutcome;
struct CharacterOutputs;

namespace session {

using SteadyTime = std::chrono::steady_clock::time_point;

// ------------------------------------------------------------------------------------------------------ events

// The kiosk started (leftovers of a crash go, retention runs once).
struct Started {
    SteadyTime now;
};
// A new fit of the current visitor was submitted: an earlier fit's folder (a retake's) goes.
struct FitSubmitted {
    std::uint64_t job;
};
// The current visitor's fit worked: its folder is written once the character is made.
struct Fitted {
    std::uint64_t job;
    std::shared_ptr<const FitOutcome> outcome;
};
// The character of a fit was made; null when the character is off or could not be made.
struct CharacterMade {
    std::uint64_t job;
    std::shared_ptr<const CharacterOutputs> character;
};
// A background write ended: the folder is complete, or absent with the error.
struct FolderWritten {
    std::uint64_t job;
    std::filesystem::path folder;
    std::optional<std::string> error;
    FlowTime t;
};
// The visitor chose to keep (the flow's SaveSession).
struct KeepAsked {
    FlowTime t;
};
// A KeepFolder command's result: kept under `code` at `keptFolder`, or refused with `error`.
struct KeepDone {
    std::uint64_t job;
    std::filesystem::path folder;   // the pending folder it was asked for
    std::string code;               // empty when refused
    std::filesystem::path keptFolder;
    std::string error;
    FlowTime t;
    std::string shareUrl{};  // the kept session's page when sharing is on (booth/share_link.h)
};
// The visitor's session is over without a keep (the flow's DiscardSession), or the run ends.
struct DiscardAsked {};
// The current visitor's style extras are ready to be written (the toon and its strip drawn, or given up).
struct StylesSettled {};
// The operator asked for disk space (after every write in flight has ended).
struct FreeDiskAsked {};
// Time passes (for the periodic retention).
struct TimePassed {
    SteadyTime now;
};

using Event = std::variant<Started, FitSubmitted, Fitted, CharacterMade, FolderWritten, KeepAsked, KeepDone,
                           DiscardAsked, StylesSettled, FreeDiskAsked, TimePassed>;

// ---------------------------------------------------------------------------------------------------- commands

// Write the session folder (in the background); answer with FolderWritten.
struct WriteFolder {
    std::uint64_t job;
    std::shared_ptr<const FitOutcome> outcome;
    std::shared_ptr<const CharacterOutputs> character;
    std::filesystem::path folder;
};
// Keep a complete pending folder under a new code (SessionStore::keep); answer with KeepDone.
struct KeepFolder {
    std::uint64_t job;
    std::filesystem::path folder;
};
// Remove a pending folder (SessionStore::discard).
struct DiscardFolder {
    std::filesystem::path folder;
};
// Write the styles' extras (the toon strip) into a kept session.
struct WriteStyleExtras {
    std::filesystem::path keptFolder;
};
// Tell the visitor flow (SessionSaved, SessionSaveFailed).
struct TellFlow {
    FlowEvent event;
};
struct RemoveLeftovers {};
struct ApplyRetention {};

using Command = std::variant<WriteFolder, KeepFolder, DiscardFolder, WriteStyleExtras, TellFlow, RemoveLeftovers,
                             ApplyRetention>;

// "KeepFolder(3, FOLDER)", for logs and test messages.
std::string describe(const Command& command);

}  // namespace session

class SessionLifecycle {
public:
    // `newPendingFolder`: a fresh folder path for the next write (SessionStore::pendingPath). `styleExtras`: kept
    // sessions get WriteStyleExtras once the styles settle (a style with extras is shown). `retentionEvery`: how
    // often retention runs while the booth is up.
    SessionLifecycle(std::function<std::filesystem::path()> newPendingFolder, bool styleExtras,
                     std::chrono::seconds retentionEvery = std::chrono::minutes(10));

    std::vector<session::Command> handle(const session::Event& event);

    // A kept session's character or folder is still on its way (the run's end waits for it).
    bool keptSessionInFlight() const;
    // A kept session still waits for its style extras (the run's end may wait for them).
    bool styleExtrasAwaited() const { return !extrasFor_.empty(); }

private:
    enum class Written { None, Writing, Done, Failed };
    struct Awaiting {
        std::uint64_t job = 0;
        std::shared_ptr<const FitOutcome> outcome;
        std::filesystem::path folder;
    };
    struct LastWrite {
        std::uint64_t job = 0;
        std::shared_ptr<const FitOutcome> outcome;
        std::shared_ptr<const CharacterOutputs> character;
    };

    void dropCurrentFolder(std::vector<session::Command>& out);
    void keepAsked(FlowTime t, std::vector<session::Command>& out);
    void written(const session::FolderWritten& e, std::vector<session::Command>& out);
    void keepDone(const session::KeepDone& e, std::vector<session::Command>& out);

    std::function<std::filesystem::path()> newPendingFolder_;
    bool styleExtras_;
    std::chrono::seconds retentionEvery_;
    std::optional<session::SteadyTime> lastRetention_;

    // The current visitor's folder: written (pendingFolder_) for writeJob_, in the state written_.
    std::filesystem::path pendingFolder_;
    std::uint64_t writeJob_ = 0;
    Written written_ = Written::None;
    std::string writeFailure_;
    std::optional<Awaiting> awaitingCharacter_;  // fitted, its write waits for the character
    std::optional<LastWrite> lastWrite_;         // what its write was given (a keep after a failed write retries)
    std::vector<std::uint64_t> keepJobs_;        // writes the visitor already chose to keep (kept when written)
    std::uint64_t styleJob_ = 0;                 // the fit the styles show
    bool stylesSettled_ = true;                  // for styleJob_
    std::filesystem::path extrasFor_;            // a kept session whose style extras are still being drawn
};

}  // namespace avatarbooth
