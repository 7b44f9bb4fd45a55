// The session folder's life: see session_lifecycle.h.
#include "booth/session_lifecycle.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <type_traits>

namespace avatarbooth {
namespace fs = std::filesystem;
using namespace session;

std::string session::describe(const Command& command) {
    return std::visit(
        [](const auto& c) -> std::string {
            using T = std::decay_t<decltype(c)>;
            if constexpr (std::is_same_v<T, WriteFolder>)
                return "WriteFolder(" + std::to_string(c.job) + " -> " + c.folder.filename().string() + ")";
            if constexpr (std::is_same_v<T, KeepFolder>)
                return "KeepFolder(" + std::to_string(c.job) + ", " + c.folder.filename().string() + ")";
            if constexpr (std::is_same_v<T, DiscardFolder>) return "DiscardFolder(" + c.folder.filename().string() + ")";
            if constexpr (std::is_same_v<T, WriteStyleExtras>)
                return "WriteStyleExtras(" + c.keptFolder.filename().string() + ")";
            if constexpr (std::is_same_v<T, TellFlow>)
                return std::holds_alternative<SessionSaved>(c.event) ? "TellFlow(saved)" : "TellFlow(save failed)";
            if constexpr (std::is_same_v<T, RemoveLeftovers>) return "RemoveLeftovers";
            if constexpr (std::is_same_v<T, ApplyRetention>) return "ApplyRetention";
        },
        command);
}

SessionLifecycle::SessionLifecycle(std::function<fs::path()> newPendingFolder, bool styleExtras,
                                   std::chrono::seconds retentionEvery)
    : newPendingFolder_(std::move(newPendingFolder)), styleExtras_(styleExtras), retentionEvery_(retentionEvery) {}

bool SessionLifecycle::keptSessionInFlight() const {
    return awaitingCharacter_ &&
           std::find(keepJobs_.begin(), keepJobs_.end(), awaitingCharacter_->job) != keepJobs_.end();
}

std::vector<Command> SessionLifecycle::handle(const Event& event) {
    std::vector<Command> out;
    std::visit(
        [&](const auto& e) {
            using T = std::decay_t<decltype(e)>;
            if constexpr (std::is_same_v<T, Started>) {
                out.push_back(RemoveLeftovers{});
                out.push_back(ApplyRetention{});
                lastRetention_ = e.now;
            } else if constexpr (std::is_same_v<T, FitSubmitted>) {
                dropCurrentFolder(out);  // a retake: the earlier fit's folder goes
            } else if constexpr (std::is_same_v<T, Fitted>) {
                if (!extrasFor_.empty() && !stylesSettled_)
                    spdlog::warn("the kept session {} goes without its style extras: the next visitor came first",
                                 extrasFor_.filename().string());
                extrasFor_.clear();
                styleJob_ = e.job;
                stylesSettled_ = false;
                pendingFolder_ = newPendingFolder_();
                writeJob_ = e.job;
                written_ = Written::Writing;  // (the write itself starts once the character is made)
                awaitingCharacter_ = Awaiting{e.job, e.outcome, pendingFolder_};
            } else if constexpr (std::is_same_v<T, CharacterMade>) {
                if (awaitingCharacter_ && awaitingCharacter_->job == e.job) {
                    out.push_back(WriteFolder{e.job, awaitingCharacter_->outcome, e.character, awaitingCharacter_->folder});
                    lastWrite_ = LastWrite{e.job, awaitingCharacter_->outcome, e.character};
                    awaitingCharacter_.reset();
                }
            } else if constexpr (std::is_same_v<T, FolderWritten>) {
                written(e, out);
            } else if constexpr (std::is_same_v<T, KeepAsked>) {
                keepAsked(e.t, out);
            } else if constexpr (std::is_same_v<T, KeepDone>) {
                keepDone(e, out);
            } else if constexpr (std::is_same_v<T, DiscardAsked>) {
                dropCurrentFolder(out);
            } else if constexpr (std::is_same_v<T, StylesSettled>) {
                stylesSettled_ = true;
                if (!extrasFor_.empty()) out.push_back(WriteStyleExtras{std::exchange(extrasFor_, {})});
            } else if constexpr (std::is_same_v<T, FreeDiskAsked>) {
                out.push_back(ApplyRetention{});
                out.push_back(RemoveLeftovers{});
            } else if constexpr (std::is_same_v<T, TimePassed>) {
                if (!lastRetention_ || e.now - *lastRetention_ >= retentionEvery_) {
                    out.push_back(ApplyRetention{});
                    lastRetention_ = e.now;
                }
            }
        },
        event);
    return out;
}

// Leaves nothing of the current visitor's folder: removed now when written, else when its write ends (a write in
// flight for no one is discarded when it reports), or never written at all when it still waits for the character.
void SessionLifecycle::dropCurrentFolder(std::vector<Command>& out) {
    lastWrite_.reset();
    if (awaitingCharacter_ && awaitingCharacter_->job == writeJob_) awaitingCharacter_.reset();
    else if (written_ != Written::Writing && !pendingFolder_.empty()) out.push_back(DiscardFolder{pendingFolder_});
    pendingFolder_.clear();
    writeJob_ = 0;
    written_ = Written::None;
}

void SessionLifecycle::keepAsked(FlowTime t, std::vector<Command>& out) {
    if (written_ == Written::Done) {
        out.push_back(KeepFolder{writeJob_, pendingFolder_});
    } else if (written_ == Written::Writing) {
        spdlog::info("the session is kept once its folder is written");
        keepJobs_.push_back(writeJob_);
    } else if (written_ == Written::Failed && lastWrite_ && lastWrite_->job == writeJob_) {
        // The write failed while the visitor looked (e.g. the disk was full): the fit is still in memory, so the
        // keep writes it again (space may have been freed since) and keeps it.
        spdlog::warn("the session folder was not written ({}): writing it again for the keep", writeFailure_);
        out.push_back(WriteFolder{writeJob_, lastWrite_->outcome, lastWrite_->character, newPendingFolder_()});
        keepJobs_.push_back(writeJob_);
    } else {
        const std::string why = written_ == Written::Failed ? writeFailure_ : "no fitted avatar to keep";
        spdlog::error("session not kept: {}", why);
        out.push_back(TellFlow{SessionSaveFailed{why, t}});
    }
    lastWrite_.reset();
    pendingFolder_.clear();
    writeJob_ = 0;
    written_ = Written::None;
}

// A finished background write: kept (the visitor already chose), held for the visitor's choice, or removed.
void SessionLifecycle::written(const FolderWritten& e, std::vector<Command>& out) {
    const auto keep = std::find(keepJobs_.begin(), keepJobs_.end(), e.job);
    if (keep != keepJobs_.end()) {
        keepJobs_.erase(keep);
        if (e.error) {
            out.push_back(DiscardFolder{e.folder});
            out.push_back(TellFlow{SessionSaveFailed{*e.error, e.t}});
        } else {
            out.push_back(KeepFolder{e.job, e.folder});
        }
    } else if (e.job == writeJob_ && written_ == Written::Writing) {
        if (e.error) {
            out.push_back(DiscardFolder{e.folder});  // (the write is atomic: this removes any staging it left)
            pendingFolder_.clear();
            written_ = Written::Failed;
            writeFailure_ = *e.error;
        } else {
            written_ = Written::Done;
        }
    } else {
        out.push_back(DiscardFolder{e.folder});  // the visitor retook a photo or left meanwhile
    }
}

void SessionLifecycle::keepDone(const KeepDone& e, std::vector<Command>& out) {
    if (e.code.empty()) {
        spdlog::error("session not kept: {}", e.error);
        out.push_back(DiscardFolder{e.folder});
        out.push_back(TellFlow{SessionSaveFailed{e.error, e.t}});
        return;
    }
    spdlog::info("session kept as {}", e.code);
    out.push_back(TellFlow{SessionSaved{e.code, e.t, e.shareUrl}});
    if (!styleExtras_ || e.job != styleJob_) return;
    if (stylesSettled_) out.push_back(WriteStyleExtras{e.keptFolder});
    else extrasFor_ = e.keptFolder;  // its extras follow once drawn
}

}  // namespace avatarbooth
