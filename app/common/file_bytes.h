// Reading a whole file into memory, with the reason in the error when it cannot be read.
#pragma once

#include <filesystem>
#include <string>

namespace avatarbooth {

// The file's bytes. Throws BoothError(BadInput) naming the file: not found, not a regular file, cannot be opened.
std::string readFileBytes(const std::filesystem::path& path);

}  // namespace avatarbooth
