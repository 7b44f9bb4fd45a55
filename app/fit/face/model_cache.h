// Files derived from a model file (a converted landmark model, dlib's decompressed face detector), kept so that a
// start reads them instead of converting again. A cache file says what it was made from (its "stamp": the source's
// path, size and modification time, or dlib's version), carries a checksum of all its bytes, and is used only when
// both match and it is this user's own file that no one else may write; otherwise it is rebuilt from the source.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace avatarbooth {

// Where the booth keeps its caches: $CACHE_DIRECTORY (systemd's CacheDirectory=, /var/cache/avatarbooth for the
// service), else /var/cache/avatarbooth when it is this user's own folder (the booth's user, running a command by
// hand), else $XDG_CACHE_HOME/avatarbooth, else ~/.cache/avatarbooth; empty when none of them is set.
std::filesystem::path defaultModelCacheDir();

// What a cache of `source` is stamped with, one line: its canonical path, size and modification time (a changed or
// replaced file has another). Nothing for a file that is not a regular file (a pipe is read once and cannot be
// stamped).
std::optional<std::string> sourceFileStamp(const std::filesystem::path& source);

// What a cache file is: its kind (at most 15 characters) and the version of that kind's layout.
struct CacheKind {
    std::string_view name;
    std::uint32_t version = 0;
};

// A cache file mapped read-only. Its payload stays valid as long as the object (the file is replaced by rename,
// never rewritten in place, so a newer cache written meanwhile does not touch these pages).
class CacheFile {
public:
    ~CacheFile();
    CacheFile(const CacheFile&) = delete;
    CacheFile& operator=(const CacheFile&) = delete;

    // The cache at `file` when it is of `kind`, made from `stamp`, whole and this user's own. Otherwise nothing,
    // with the reason in `why` (empty when the file does not exist).
    static std::unique_ptr<const CacheFile> open(const std::filesystem::path& file, const CacheKind& kind,
                                                 std::string_view stamp, std::string& why);
    // Writes a cache of `kind` made from `stamp` (temporary name, then rename; mode 0600), its payload the pieces
    // one after the other, each starting at a multiple of 64 bytes from the payload's start. Creates the folder
    // (mode 0700) when missing. Throws BoothError(Output) naming the file.
    static void write(const std::filesystem::path& file, const CacheKind& kind, std::string_view stamp,
                      std::span<const std::string_view> pieces);

    // The payload; its start is aligned to 64 bytes.
    std::span<const std::byte> payload() const { return payload_; }

    static constexpr std::size_t kAlignment = 64;

private:
    CacheFile(void* map, std::size_t size, std::span<const std::byte> payload);
    void* map_;
    std::size_t size_;
    std::span<const std::byte> payload_;
};

}  // namespace avatarbooth
