// Writing results so that a crash, a full disk or a bad input never leaves a half-written file or folder:
// everything goes to a temporary name first and is renamed into place when complete.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace avatarbooth {

// Writes bytes to path through path.tmp-XXXX + fsync + rename. Throws BoothError(Output) naming the file.
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

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
