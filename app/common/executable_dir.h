// The folder of the running executable, for files installed beside it (<exe>/../share/avatarbooth/...).
#pragma once

#include <filesystem>

namespace avatarbooth {

// Empty when /proc/self/exe cannot be read.
std::filesystem::path executableDir();

}  // namespace avatarbooth
