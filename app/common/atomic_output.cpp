// Temporary-name-then-rename writing of files and folders.
#include "common/atomic_output.h"

#include "common/error.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <random>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

std::string randomSuffix() {
    static thread_local std::mt19937_64 rng{std::random_device{}()};
    static constexpr char kDigits[] = "0123456789abcdefghijklmnopqrstuvwxyz";
    std::string s(8, '0');
    for (auto& c : s) c = kDigits[rng() % (sizeof kDigits - 1)];
    return s;
}

[[noreturn]] void failOutput(const fs::path& path, const std::string& what, int err) {
    throw BoothError(ErrorKind::Output, path.string(), what + ": " + std::strerror(err));
}

void fsyncDirectory(const fs::path& dir) {
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
}

// The injected failure: writes left before it strikes (-1: none injected), the errno it fails with, and a count.
std::atomic<int> gWritesBeforeFailure{-1};
std::atomic<int> gInjectedError{0};
std::atomic<int> gInjectedFailures{0};

// Whether this write is to fail by injection (consumes one allowed write otherwise).
bool injectedFailureDue() {
    int left = gWritesBeforeFailure.load();
    while (left > 0 && !gWritesBeforeFailure.compare_exchange_weak(left, left - 1)) {
    }
    return left == 0;
}

}  // namespace

void injectWriteFailure(int afterWrites, int error) {
    gInjectedError = error;
    gInjectedFailures = 0;
    gWritesBeforeFailure = std::max(0, afterWrites);
}

void clearInjectedWriteFailure() { gWritesBeforeFailure = -1; }

int injectedWriteFailures() { return gInjectedFailures.load(); }

void writeFileAtomically(const fs::path& path, std::string_view bytes) {
    writeFileAtomically(path, std::span<const std::string_view>(&bytes, 1));
}

void writeFileAtomically(const fs::path& path, std::span<const std::string_view> pieces) {
    const fs::path tmp = path.string() + ".tmp-" + randomSuffix();
    // 0600: outputs hold photos of visitors, personal data readable only by the booth's user.
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0) failOutput(path, "cannot create", errno);
    const bool injected = injectedFailureDue();
    const auto fail = [&](int err) {
        ::close(fd);
        ::unlink(tmp.c_str());
        failOutput(path, "cannot write", err);
    };
    for (const std::string_view bytes : pieces) {
        std::size_t done = 0;
        while (done < bytes.size() || injected) {
            // An injected failure strikes after half the bytes, as a disk filling up in the middle of a file does.
            const std::size_t chunk = injected ? (bytes.size() - done) / 2 : bytes.size() - done;
            ssize_t n = ::write(fd, bytes.data() + done, chunk);
            if (injected && n >= 0) {
                ++gInjectedFailures;
                n = -1;
                errno = gInjectedError.load();
            }
            if (n < 0) {
                if (errno == EINTR) continue;
                fail(errno);
            }
            done += static_cast<std::size_t>(n);
        }
    }
    if (injected) {  // a file of no bytes at all fails too
        ++gInjectedFailures;
        fail(gInjectedError.load());
    }
    if (::fsync(fd) != 0 || ::close(fd) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        failOutput(path, "cannot write", err);
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        failOutput(path, "cannot rename into place", err);
    }
}

StagedDirectory::StagedDirectory(fs::path finalPath, std::string markerFile) : final_(std::move(finalPath)) {
    std::error_code ec;
    if (fs::exists(final_, ec)) {
        if (!fs::is_directory(final_, ec))
            throw BoothError(ErrorKind::Output, final_.string(), "exists and is not a folder");
        if (!fs::is_empty(final_, ec) && !fs::exists(final_ / markerFile, ec))
            throw BoothError(ErrorKind::Output, final_.string(),
                             "exists, is not empty and is not an earlier result (no " + markerFile +
                                 "); choose another output folder");
    }
    const fs::path parent = final_.has_parent_path() ? final_.parent_path() : fs::path(".");
    fs::create_directories(parent, ec);
    if (ec) throw BoothError(ErrorKind::Output, parent.string(), "cannot create folder: " + ec.message());
    staging_ = parent / ("." + final_.filename().string() + ".partial-" + randomSuffix());
    if (::mkdir(staging_.c_str(), 0700) != 0) failOutput(staging_, "cannot create folder", errno);
}

StagedDirectory::~StagedDirectory() {
    if (!committed_) {
        std::error_code ec;
        fs::remove_all(staging_, ec);
    }
}

void StagedDirectory::commit() {
    // Make the files durable before the folder appears under its final name.
    for (const auto& entry : fs::directory_iterator(staging_)) {
        const int fd = ::open(entry.path().c_str(), O_RDONLY | O_CLOEXEC);
        if (fd >= 0) {
            ::fsync(fd);
            ::close(fd);
        }
    }
    fsyncDirectory(staging_);
    std::error_code ec;
    if (fs::exists(final_, ec)) {
        // Swap the earlier result out in one step, then remove it: the final name always holds a whole result.
        if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) != 0)
            failOutput(final_, "cannot replace the earlier result", errno);
        fs::remove_all(staging_, ec);
    } else if (::rename(staging_.c_str(), final_.c_str()) != 0) {
        failOutput(final_, "cannot move the finished result into place", errno);
    }
    committed_ = true;
    fsyncDirectory(final_.has_parent_path() ? final_.parent_path() : fs::path("."));
}

}  // namespace avatarbooth
