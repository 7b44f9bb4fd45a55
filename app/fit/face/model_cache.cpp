// Cache files of converted models: a 64-byte header, the stamp of the source, the payload; mapped read-only.
#include "fit/face/model_cache.h"

#include "common/atomic_output.h"
#include "common/error.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'a', 'v', 'b', 'c', 'a', 'c', 'h', 'e'};
constexpr std::uint32_t kByteOrder = 0x01020304;  // reads otherwise on a machine of the other byte order

struct Header {
    char magic[8];
    std::uint32_t byteOrder;
    std::uint32_t version;  // of the kind's payload layout
    char kind[16];          // zero-padded
    std::uint32_t stampBytes;
    std::uint32_t reserved;
    std::uint64_t payloadOffset;  // a multiple of kAlignment, after the stamp
    std::uint64_t payloadBytes;   // to the end of the file
    std::uint64_t checksum;       // of the whole file, this field taken as zero
};
static_assert(sizeof(Header) == 64);

std::size_t padded(std::size_t n) {
    constexpr std::size_t a = CacheFile::kAlignment;
    return (n + a - 1) / a * a;
}

// A 64-bit checksum in four lanes of 8-byte words (fast enough to check 33 MB in a few milliseconds). Each step,
// lane = (lane ^ word) * odd, is a bijection of the lane for any word and of the word for any lane, so a change
// confined to one word always reaches the sum; it guards against damage on disk, not against tampering (the file
// is this user's own).
class Checksum {
public:
    void add(const void* data, std::size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        total_ += n;
        if (buffered_ > 0) {
            const std::size_t take = std::min(n, block_.size() - buffered_);
            std::memcpy(block_.data() + buffered_, p, take);
            buffered_ += take;
            p += take;
            n -= take;
            if (buffered_ < block_.size()) return;
            addBlock(block_.data());
            buffered_ = 0;
        }
        for (; n >= block_.size(); p += block_.size(), n -= block_.size()) addBlock(p);
        std::memcpy(block_.data(), p, n);
        buffered_ = n;
    }
    std::uint64_t sum() const {
        Checksum last = *this;
        if (last.buffered_ > 0) {
            std::memset(last.block_.data() + last.buffered_, 0, last.block_.size() - last.buffered_);
            last.addBlock(last.block_.data());
        }
        std::uint64_t h = last.total_;
        for (const std::uint64_t lane : last.lanes_) h = (h ^ lane) * kOdd, h ^= h >> 29;
        return h;
    }

private:
    static constexpr std::uint64_t kOdd = 0x9e3779b97f4a7c15ull;
    void addBlock(const unsigned char* p) {
        for (std::size_t k = 0; k < lanes_.size(); ++k) {
            std::uint64_t word;
            std::memcpy(&word, p + 8 * k, 8);
            lanes_[k] = (lanes_[k] ^ word) * kOdd;
        }
    }
    std::array<std::uint64_t, 4> lanes_{1, 2, 3, 4};
    std::array<unsigned char, 32> block_{};
    std::size_t buffered_ = 0;
    std::uint64_t total_ = 0;
};

Header headerFor(const CacheKind& kind, std::string_view stamp, std::uint64_t payloadBytes) {
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.byteOrder = kByteOrder;
    h.version = kind.version;
    std::memcpy(h.kind, kind.name.data(), std::min(kind.name.size(), sizeof h.kind - 1));
    h.stampBytes = static_cast<std::uint32_t>(stamp.size());
    h.payloadOffset = padded(sizeof(Header) + stamp.size());
    h.payloadBytes = payloadBytes;
    return h;
}

std::string kindName(const Header& h) { return std::string(h.kind, strnlen(h.kind, sizeof h.kind)); }

// Closes a descriptor when it goes out of scope.
struct Fd {
    int fd;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};

}  // namespace

fs::path defaultModelCacheDir() {
    // systemd may list several folders, ':'-separated: the first is the unit's own.
    if (const char* s = std::getenv("CACHE_DIRECTORY"); s && *s) {
        const std::string first(s, strcspn(s, ":"));
        if (fs::path(first).is_absolute()) return first;
    }
    // The package's (tmpfiles.d): the booth's user running a command by hand fills the cache the service reads.
    static constexpr const char* kInstalled = "/var/cache/avatarbooth";
    if (struct stat st {}; ::stat(kInstalled, &st) == 0 && S_ISDIR(st.st_mode) && st.st_uid == ::geteuid())
        return kInstalled;
    // The XDG base directory specification: relative paths are to be ignored.
    if (const char* s = std::getenv("XDG_CACHE_HOME"); s && fs::path(s).is_absolute())
        return fs::path(s) / "avatarbooth";
    if (const char* s = std::getenv("HOME"); s && fs::path(s).is_absolute())
        return fs::path(s) / ".cache" / "avatarbooth";
    return {};
}

std::optional<std::string> sourceFileStamp(const fs::path& source) {
    struct stat st {};
    if (::stat(source.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
    std::error_code ec;
    const fs::path canonical = fs::canonical(source, ec);
    char modified[32];
    std::snprintf(modified, sizeof modified, "%lld.%09ld", static_cast<long long>(st.st_mtim.tv_sec),
                  static_cast<long>(st.st_mtim.tv_nsec));
    return (ec ? fs::absolute(source, ec) : canonical).string() + ", " + std::to_string(st.st_size) +
           " bytes, modified " + modified;
}

CacheFile::CacheFile(void* map, std::size_t size, std::span<const std::byte> payload)
    : map_(map), size_(size), payload_(payload) {}

CacheFile::~CacheFile() { ::munmap(map_, size_); }

std::unique_ptr<const CacheFile> CacheFile::open(const fs::path& file, const CacheKind& kind, std::string_view stamp,
                                                 std::string& why) {
    why.clear();
    // Not through a symbolic link: the cache is the file at this name, which a rebuild replaces.
    const Fd in{::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW)};
    if (in.fd < 0) {
        if (errno == ELOOP) why = "is a symbolic link";
        else if (errno != ENOENT) why = std::string("cannot be opened: ") + std::strerror(errno);
        return nullptr;
    }
    struct stat st {};
    if (::fstat(in.fd, &st) != 0) {
        why = std::string("cannot be read: ") + std::strerror(errno);
        return nullptr;
    }
    if (!S_ISREG(st.st_mode)) {
        why = "is not a regular file";
        return nullptr;
    }
    if (st.st_uid != ::geteuid() || (st.st_mode & (S_IWGRP | S_IWOTH)) != 0) {
        why = "is not this user's own file, or others may write it";
        return nullptr;
    }
    const auto size = static_cast<std::size_t>(st.st_size);
    Header h{};
    std::string theirStamp;
    if (size < sizeof h || ::pread(in.fd, &h, sizeof h, 0) != static_cast<ssize_t>(sizeof h)) {
        why = "is truncated (" + std::to_string(size) + " bytes)";
        return nullptr;
    }
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) {
        why = "is not an avatarbooth cache file";
        return nullptr;
    }
    if (h.byteOrder != kByteOrder) {
        why = "was written on a machine of another byte order";
        return nullptr;
    }
    if (kindName(h) != kind.name || h.version != kind.version) {
        why = "holds a " + kindName(h) + " of layout " + std::to_string(h.version) + " (" + std::string(kind.name) +
              " " + std::to_string(kind.version) + " expected)";
        return nullptr;
    }
    if (h.stampBytes > size - sizeof h || h.payloadOffset != padded(sizeof h + h.stampBytes) ||
        h.payloadOffset > size || h.payloadBytes != size - h.payloadOffset) {
        why = "is truncated or damaged (" + std::to_string(size) + " bytes, its header says " +
              std::to_string(h.payloadOffset + h.payloadBytes) + ")";
        return nullptr;
    }
    theirStamp.resize(h.stampBytes);
    if (::pread(in.fd, theirStamp.data(), theirStamp.size(), sizeof h) != static_cast<ssize_t>(theirStamp.size())) {
        why = "cannot be read to its end";
        return nullptr;
    }
    if (theirStamp != stamp) {
        why = "is stale: it was made from " + theirStamp;
        return nullptr;
    }
    // Read in whole at once: the checksum reads every page anyway.
    void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, in.fd, 0);
    if (map == MAP_FAILED) {
        why = std::string("cannot be mapped: ") + std::strerror(errno);
        return nullptr;
    }
    const auto* bytes = static_cast<const std::byte*>(map);
    std::unique_ptr<const CacheFile> cache(
        new CacheFile(map, size, std::span<const std::byte>(bytes + h.payloadOffset, h.payloadBytes)));
    Header zeroed = h;
    zeroed.checksum = 0;
    Checksum sum;
    sum.add(&zeroed, sizeof zeroed);
    sum.add(bytes + sizeof h, size - sizeof h);
    if (sum.sum() != h.checksum) {
        why = "is damaged (its checksum does not match)";
        return nullptr;
    }
    return cache;
}

void CacheFile::write(const fs::path& file, const CacheKind& kind, std::string_view stamp,
                      std::span<const std::string_view> pieces) {
    static constexpr char kZeros[kAlignment] = {};
    std::vector<std::string_view> parts;
    parts.reserve(2 * pieces.size() + 3);
    parts.emplace_back();  // the header, once the checksum is known
    parts.push_back(stamp);
    const std::size_t payloadOffset = padded(sizeof(Header) + stamp.size());
    parts.emplace_back(kZeros, payloadOffset - sizeof(Header) - stamp.size());
    std::size_t payloadBytes = 0;
    for (const std::string_view piece : pieces) {
        parts.push_back(piece);
        parts.emplace_back(kZeros, padded(piece.size()) - piece.size());
        payloadBytes += padded(piece.size());
    }
    Header h = headerFor(kind, stamp, payloadBytes);
    Checksum sum;
    sum.add(&h, sizeof h);
    for (std::size_t k = 1; k < parts.size(); ++k) sum.add(parts[k].data(), parts[k].size());
    h.checksum = sum.sum();
    parts[0] = std::string_view(reinterpret_cast<const char*>(&h), sizeof h);

    // The folder is the booth user's alone: what is found in it is trusted (open() checks only for damage).
    const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
        if (dir.has_parent_path()) fs::create_directories(dir.parent_path(), ec);
        if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST)
            throw BoothError(ErrorKind::Output, dir.string(),
                             std::string("cannot create folder: ") + std::strerror(errno));
    }
    writeFileAtomically(file, parts);
}

}  // namespace avatarbooth
