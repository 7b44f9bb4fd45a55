// Kept sessions: short codes, keep/discard, retention (see session_store.h for the layout and the rules).
#include "booth/session_store.h"

#include "booth/share_link.h"

#include "common/atomic_output.h"
#include "common/error.h"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

constexpr const char* kSessionFile = "session.json";
constexpr const char* kFitMarker = "fit.json";

[[noreturn]] void failOutput(const fs::path& path, const std::string& what, int err = 0) {
    throw BoothError(ErrorKind::Output, path.string(), err ? what + ": " + std::strerror(err) : what);
}

bool isCodeName(const std::string& name, int length) {
    return normalizeCode(name, length) == name;
}

// Everything under `root` (root included) to 0700 folders / 0600 files, without following links.
void restrictModes(const fs::path& root) {
    auto set = [](const fs::path& p, mode_t mode) {
        if (::chmod(p.c_str(), mode) != 0) failOutput(p, "cannot set permissions", errno);
    };
    set(root, 0700);
    for (const auto& e : fs::recursive_directory_iterator(root)) {
        if (e.is_symlink()) continue;
        set(e.path(), e.is_directory() ? 0700 : 0600);
    }
}

void fsyncDirectory(const fs::path& dir) {
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
}

std::uintmax_t treeBytes(const fs::path& p) {
    std::error_code ec;
    if (fs::is_regular_file(fs::symlink_status(p, ec))) return fs::file_size(p, ec);
    std::uintmax_t sum = 0;
    for (auto it = fs::recursive_directory_iterator(p, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec))
        if (it->is_regular_file(ec)) sum += it->file_size(ec);
    return sum;
}

// Is `p` strictly inside `dir` (after making both absolute and normal)?
bool isInside(const fs::path& p, const fs::path& dir) {
    const fs::path a = fs::absolute(p).lexically_normal(), d = fs::absolute(dir).lexically_normal();
    const auto rel = a.lexically_relative(d);
    return !rel.empty() && *rel.begin() != ".." && *rel.begin() != ".";
}

}  // namespace

std::string makeShortCode(const std::function<std::uint32_t()>& random, int length) {
    std::string code;
    code.reserve(static_cast<std::size_t>(std::max(0, length)));
    for (int i = 0; i < length; ++i) code.push_back(kCodeAlphabet[random() % kCodeAlphabet.size()]);
    return code;
}

std::optional<std::string> normalizeCode(std::string_view typed, int length) {
    std::string code;
    for (char c : typed) {
        if (c == ' ' || c == '-' || c == '\t' || c == '\n' || c == '\r') continue;
        const char u = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        if (kCodeAlphabet.find(u) == std::string_view::npos) return std::nullopt;
        code.push_back(u);
    }
    if (static_cast<int>(code.size()) != length) return std::nullopt;
    return code;
}

bool isPhotoFile(const fs::path& name) {
    const std::string stem = name.stem().string();
    const std::string file = name.filename().string();
    if (file.empty() || file[0] == '.') return false;
    if (stem == "front" || stem == "side" || stem == "background") return name.has_extension();
    const std::string overlay = "_overlay";
    return stem.size() > overlay.size() && stem.compare(stem.size() - overlay.size(), overlay.size(), overlay) == 0;
}

SessionStore::SessionStore(SessionStoreSettings settings, std::function<std::uint32_t()> random)
    : settings_(std::move(settings)), random_(std::move(random)) {
    if (settings_.codeLength < 4 || settings_.codeLength > 16)
        throw BoothError(ErrorKind::BadConfig, "sessions.code_length",
                         "must be 4-16 characters, not " + std::to_string(settings_.codeLength));
    if (!random_) {
        auto device = std::make_shared<std::random_device>();
        random_ = [device] { return static_cast<std::uint32_t>((*device)()); };
    }
}

void SessionStore::ensureDirectory(const fs::path& dir) const {
    std::error_code ec;
    if (fs::is_directory(dir, ec)) return;
    if (dir != settings_.directory) ensureDirectory(settings_.directory);
    fs::create_directories(dir, ec);
    if (ec) failOutput(dir, "cannot create folder: " + ec.message());
    if (::chmod(dir.c_str(), 0700) != 0) failOutput(dir, "cannot set permissions", errno);
}

fs::path SessionStore::pendingPath() {
    ensureDirectory(pendingDir());
    for (;;) {
        const fs::path p = pendingDir() / makeShortCode(random_, 12);
        std::error_code ec;
        if (!fs::exists(p, ec)) return p;
    }
}

std::string SessionStore::keep(const fs::path& fitFolder, WallTime now) {
    std::error_code ec;
    if (!isInside(fitFolder, pendingDir()))
        failOutput(fitFolder, "is not a pending fit of this store (" + pendingDir().string() + ")");
    if (!fs::is_regular_file(fitFolder / kFitMarker, ec))
        failOutput(fitFolder, "is not a complete fit folder (no fit.json)");

    std::string code;
    for (int attempt = 0;; ++attempt) {
        code = makeShortCode(random_, settings_.codeLength);
        if (!fs::exists(settings_.directory / code, ec)) break;
        if (attempt > 1000) failOutput(settings_.directory, "no free session code after 1000 attempts");
    }
    const auto keptSeconds = std::chrono::duration_cast<std::chrono::seconds>(now.time_since_epoch()).count();
    // The visitor's page key (booth/share_link.h), drawn for every kept session: it is what makes the page's URL
    // unguessable whether or not sharing is on now (the operator may turn it on later).
    nlohmann::json info{{"code", code}, {"kept_at", keptSeconds}, {"share_token", makeShareToken()}};
    writeFileAtomically(fitFolder / kSessionFile, info.dump(2) + "\n");
    restrictModes(fitFolder);
    // RENAME_NOREPLACE: two booths sharing a folder (or a code drawn twice) can never overwrite a session.
    while (::renameat2(AT_FDCWD, fitFolder.c_str(), AT_FDCWD, (settings_.directory / code).c_str(),
                       RENAME_NOREPLACE) != 0) {
        if (errno != EEXIST) failOutput(settings_.directory / code, "cannot move the session into place", errno);
        code = makeShortCode(random_, settings_.codeLength);
        info["code"] = code;
        writeFileAtomically(fitFolder / kSessionFile, info.dump(2) + "\n");
    }
    fsyncDirectory(settings_.directory);
    return code;
}

void SessionStore::discard(const fs::path& fitFolder) {
    if (!isInside(fitFolder, pendingDir()))
        throw BoothError(ErrorKind::Internal, fitFolder.string(),
                         "refusing to delete: not a pending fit of this store (" + pendingDir().string() + ")");
    std::error_code ec;
    fs::remove_all(fitFolder, ec);
    if (ec) failOutput(fitFolder, "cannot delete: " + ec.message());
    // StagedDirectory's partial folders are siblings named ".<name>.partial-*".
    const std::string partial = "." + fitFolder.filename().string() + ".partial-";
    for (const auto& e : fs::directory_iterator(fitFolder.parent_path(), ec))
        if (e.path().filename().string().rfind(partial, 0) == 0) fs::remove_all(e.path(), ec);
}

WallTime SessionStore::keptAt(const fs::path& folder) const {
    std::ifstream in(folder / kSessionFile);
    if (in) {
        try {
            const auto j = nlohmann::json::parse(in);
            return WallTime(std::chrono::seconds(j.at("kept_at").get<long long>()));
        } catch (const std::exception&) {
            // a damaged session.json: fall back to the folder's time below
        }
    }
    std::error_code ec;
    const auto ft = fs::last_write_time(folder, ec);
    if (ec) return WallTime{};
    return std::chrono::time_point_cast<WallTime::duration>(std::chrono::file_clock::to_sys(ft));
}

RetentionReport SessionStore::applyRetention(WallTime now) {
    RetentionReport report;
    std::error_code ec;
    if (!fs::is_directory(settings_.directory, ec)) return report;
    for (const StoredSession& s : list()) {
        const auto age = now - s.keptAt;
        if (settings_.sessionRetention.count() > 0 && age >= settings_.sessionRetention) {
            // Renamed out of the way first: a crash mid-delete leaves a .trash folder, never half a session.
            const fs::path trash = settings_.directory / (".trash-" + s.code + "-" + makeShortCode(random_, 6));
            if (::rename(s.folder.c_str(), trash.c_str()) != 0) failOutput(s.folder, "cannot delete", errno);
            report.bytesFreed += treeBytes(trash);
            fs::remove_all(trash, ec);
            if (ec) failOutput(trash, "cannot delete: " + ec.message());
            ++report.sessionsDeleted;
        } else if (settings_.photoRetention.count() > 0 && age >= settings_.photoRetention && s.hasPhotos) {
            for (const auto& e : fs::directory_iterator(s.folder)) {
                if (!e.is_regular_file() || !isPhotoFile(e.path().filename())) continue;
                const auto bytes = e.file_size();
                if (!fs::remove(e.path(), ec) || ec) failOutput(e.path(), "cannot delete: " + ec.message());
                report.bytesFreed += bytes;
                ++report.photosDeleted;
            }
            fsyncDirectory(s.folder);
        }
    }
    return report;
}

int SessionStore::removeLeftovers() {
    int removed = 0;
    std::error_code ec;
    if (!fs::is_directory(settings_.directory, ec)) return 0;
    for (const auto& e : fs::directory_iterator(settings_.directory)) {
        if (e.path().filename().string().rfind(".trash-", 0) != 0) continue;
        fs::remove_all(e.path(), ec);
        if (ec) failOutput(e.path(), "cannot delete: " + ec.message());
        ++removed;
    }
    if (fs::is_directory(pendingDir(), ec)) {
        for (const auto& e : fs::directory_iterator(pendingDir())) {
            fs::remove_all(e.path(), ec);
            if (ec) failOutput(e.path(), "cannot delete: " + ec.message());
            ++removed;
        }
    }
    // A kept session gets its toon strip after the keep (the toon may still be drawing then): a half-written one
    // (".toon.partial-…", see StagedDirectory) is all such a late addition can leave.
    std::vector<fs::path> partial;
    for (const StoredSession& kept : list())
        for (const auto& e : fs::directory_iterator(kept.folder, ec))
            if (e.path().filename().string().find(".partial-") != std::string::npos) partial.push_back(e.path());
    for (const fs::path& p : partial) {
        fs::remove_all(p, ec);
        if (ec) failOutput(p, "cannot delete: " + ec.message());
        ++removed;
    }
    return removed;
}

std::vector<StoredSession> SessionStore::list() const {
    std::vector<StoredSession> out;
    std::error_code ec;
    if (!fs::is_directory(settings_.directory, ec)) return out;
    for (const auto& e : fs::directory_iterator(settings_.directory)) {
        const std::string name = e.path().filename().string();
        if (!e.is_directory() || !isCodeName(name, settings_.codeLength)) continue;
        StoredSession s;
        s.code = name;
        s.folder = e.path();
        s.keptAt = keptAt(e.path());
        for (const auto& f : fs::directory_iterator(e.path()))
            if (f.is_regular_file() && isPhotoFile(f.path().filename())) s.hasPhotos = true;
        out.push_back(std::move(s));
    }
    std::sort(out.begin(), out.end(), [](const StoredSession& a, const StoredSession& b) {
        return a.keptAt != b.keptAt ? a.keptAt > b.keptAt : a.code < b.code;
    });
    return out;
}

std::optional<fs::path> SessionStore::find(std::string_view typed) const {
    const auto code = normalizeCode(typed, settings_.codeLength);
    if (!code) return std::nullopt;
    const fs::path p = settings_.directory / *code;
    std::error_code ec;
    if (!fs::is_directory(p, ec)) return std::nullopt;
    return p;
}

std::uintmax_t SessionStore::freeBytes() const {
    std::error_code ec;
    fs::path p = settings_.directory;
    while (!p.empty() && !fs::exists(p, ec)) p = p.parent_path();
    const auto info = fs::space(p.empty() ? fs::path(".") : p, ec);
    return ec ? 0 : info.available;
}

}  // namespace avatarbooth
