// Writing results so that a crash, a full disk or a bad input never leaves a half-written file or folder:
// everything goes to a temporary name first and is renamed into place when complete.
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <string_view>

namespace avatarbooth {

// Writes bytes to path through path.tmp-XXXX + fsync + rename. Throws BoothError(Output) naming the file.
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);
// The same for a file made of several pieces, written one after the other (large arrays need no joined copy).
void writeFileAtomically(const std::filesystem::path& path, std::span<const std::string_view> pieces);

// Fault injection for the reliability tests (tests/reliability/): after `afterWrites` more successful
// writeFileAtomically() calls, every later call fails as write(2) failing with `error` would (ENOSPC: the disk is
// full), leaving no file behind, until clearInjectedWriteFailure(). Process-wide; off unless a test turns it on.
void injectWriteFailure(int afterWrites, int error);
void clearInjectedWriteFailure();
// Writes refused by the injected failure since it was last injected.
int injectedWriteFailures();

// An output folder under construction. Files go into staging(); commit() moves the folder to its final name in
// one step (replacing an earlier result of ours there). If commit() is never called, the staging folder is
// removed and the final name is left untouched.
class StagedDirectory {
public:
    // Refuses (BoothError Output) when `finalPath` exists and is neither empty nor an earlier result (a folder
    // holding `markerFile`), so that a typo never replaces someone's folder.
    StagedDirectory(std::filesystem::path finalPath, std::string markerFile);
    ~StagedDirectory();
    StagedDirectory(const StagedDirectory&) = delete;
    StagedDirectory& operator=(const StagedDirectory&) = delete;

    const std::filesystem::path& staging() const { return staging_; }
    const std::filesystem::path& finalPath() const { return final_; }
    void commit();

private:
    std::filesystem::path final_;
    std::filesystem::path staging_;
    bool committed_ = false;
};

}  // namespace avatarbooth
