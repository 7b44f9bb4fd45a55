// Reading a whole file into memory.
#include "common/file_bytes.h"

#include "common/error.h"

#include <fstream>
#include <iterator>

namespace avatarbooth {
namespace fs = std::filesystem;

std::string readFileBytes(const fs::path& path) {
    const auto bad = [&](const char* why) { return BoothError(ErrorKind::BadInput, path.string(), why); };
    std::error_code ec;
    if (!fs::exists(path, ec)) throw bad("file not found");
    if (!fs::is_regular_file(path, ec)) throw bad("is not a regular file (a folder with a file's name?)");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw bad("cannot be opened (permissions?)");
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw bad("could not be read to its end");
    return bytes;
}

}  // namespace avatarbooth
