// Kept sessions on disk: a fit's output folder moved under a short code the visitor is shown, readable only by the
// booth's user, and deleted again by the retention rules (photos first, the avatar later).
//
// Layout under SessionStoreSettings::directory:
//   <CODE>/          a kept session: the session folder (booth/session_folder.h) plus session.json (code, kept_at,
//                    share_token: the key to the visitor's page, booth/share_link.h)
//   .pending/<id>/   a fit of the visitor at the booth, not kept yet (writeSessionFolder creates it atomically)
//   .trash-<CODE>-*  a session being deleted (renamed first, so a crash never leaves half a session under a code)
// Folders are 0700 and files 0600: the photos are personal data.
//
// Retention (the choice, and why): a session's photos (front.*, side.*, background.*, *_overlay.*) are deleted
// photoRetention after it was kept (default 24 h: enough to collect the avatar the same day); the rest (avatar.glb,
// previews, landmarks.json, fit.json, session.json) sessionRetention after it was kept (default 30 days). The
// avatar's texture is made from the photos, so it is personal data too and is not kept forever by default; set
// sessionRetention to 0 to keep avatars until the operator deletes them.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace avatarbooth {

using WallTime = std::chrono::system_clock::time_point;

struct SessionStoreSettings {
    // Where kept sessions live (created 0700 when missing).
    std::filesystem::path directory = "/var/lib/avatarbooth/sessions";
    // Photos are deleted this long after the session was kept; 0: never.
    std::chrono::seconds photoRetention = std::chrono::hours(24);
    // The whole session is deleted this long after it was kept; 0: never (keep avatars).
    std::chrono::seconds sessionRetention = std::chrono::hours(24 * 30);
    // Characters in a session's code (from kCodeAlphabet: 32^6, about 10^9 codes).
    int codeLength = 6;
};

// Upper-case letters and digits without the look-alikes 0/O and 1/I.
inline constexpr std::string_view kCodeAlphabet = "23456789ABCDEFGHJKLMNPQRSTUVWXYZ";

// A code of `length` characters of kCodeAlphabet, each from random() % 32.
std::string makeShortCode(const std::function<std::uint32_t()>& random, int length);

// A code as an operator typed it ("ab3k7z ", "AB3-K7Z"): upper-cased, spaces and dashes dropped; nothing when a
// character is outside kCodeAlphabet or the length is not `length`.
std::optional<std::string> normalizeCode(std::string_view typed, int length);

// Whether a file of a session folder is a photo (or drawn on a photo) for retention: front.*, side.*,
// background.*, *_overlay.*.
bool isPhotoFile(const std::filesystem::path& name);

struct StoredSession {
    std::string code;
    std::filesystem::path folder;
    WallTime keptAt;
    bool hasPhotos = false;
};

struct RetentionReport {
    int photosDeleted = 0;     // files
    int sessionsDeleted = 0;   // whole sessions
    std::uintmax_t bytesFreed = 0;
};

class SessionStore {
public:
    // random: the source of codes and pending names (default: std::random_device); tests inject their own.
    explicit SessionStore(SessionStoreSettings settings, std::function<std::uint32_t()> random = {});

    const SessionStoreSettings& settings() const { return settings_; }

    // A fresh, not yet existing folder path under .pending/ for the next fit's output.
    std::filesystem::path pendingPath();

    // Keeps a complete fit folder (one holding fit.json) that lies under .pending/: writes session.json, makes it
    // 0700/0600, and moves it under a new code in one rename. Returns the code.
    // Throws BoothError(Output) naming the folder when it is missing, incomplete, outside .pending/, or the move
    // fails.
    std::string keep(const std::filesystem::path& fitFolder, WallTime now);

    // Deletes a pending fit folder and anything it left (partial staging folders); nothing remains. A path outside
    // .pending/ is refused (BoothError(Internal)): this never deletes a kept session.
    void discard(const std::filesystem::path& fitFolder);

    // Applies the retention rules at `now` (the kiosk calls it periodically, e.g. every 10 minutes).
    RetentionReport applyRetention(WallTime now);

    // Deletes what a crash left: every pending fit, every half-deleted session and any half-written addition to a
    // kept session (its toon strip). Returns the folders removed.
    int removeLeftovers();

    // Kept sessions, newest first.
    std::vector<StoredSession> list() const;
    // The session folder for a code as typed (see normalizeCode).
    std::optional<std::filesystem::path> find(std::string_view typed) const;
    // Bytes free for the booth's user on the sessions' filesystem.
    std::uintmax_t freeBytes() const;

private:
    std::filesystem::path pendingDir() const { return settings_.directory / ".pending"; }
    void ensureDirectory(const std::filesystem::path& dir) const;
    WallTime keptAt(const std::filesystem::path& folder) const;

    SessionStoreSettings settings_;
    std::function<std::uint32_t()> random_;
};

}  // namespace avatarbooth
