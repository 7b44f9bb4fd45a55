// Reading /proc/self/status and /proc/self/fd.
#include "sim/process_figures.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace avatarbooth {

ProcessFigures readProcessFigures() {
    ProcessFigures f;
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line)) {
        std::istringstream fields(line);
        std::string key;
        double value = 0.0;
        fields >> key >> value;
        if (key == "VmRSS:") f.rssMegabytes = value / 1024.0;
        else if (key == "VmHWM:") f.peakRssMegabytes = value / 1024.0;
        else if (key == "RssAnon:") f.anonRssMegabytes = value / 1024.0;
        else if (key == "RssFile:") f.fileRssMegabytes = value / 1024.0;
        else if (key == "Threads:") f.threads = static_cast<int>(value);
    }
    std::error_code ec;
    for (auto it = std::filesystem::directory_iterator("/proc/self/fd", ec);
         !ec && it != std::filesystem::directory_iterator(); it.increment(ec))
        ++f.openFiles;
    if (f.openFiles > 0) --f.openFiles;  // the iterator's own descriptor
    return f;
}

namespace {

// What an anonymous mapping most likely holds: glibc's thread arenas are heaps aligned to their 64 MB maximum
// size; executable ones are code compiled at run time (llvmpipe's shaders); the rest are blocks above the mmap
// threshold (images), thread stacks and the drivers' own mappings.
std::string anonymousKind(const std::string& range, const std::string& perms) {
    const unsigned long long start = std::stoull(range.substr(0, range.find('-')), nullptr, 16);
    if (perms.find('x') != std::string::npos) return "[anon: code]";
    if (start % (64ULL << 20) == 0) return "[anon: arena]";
    return "[anon]";
}

}  // namespace

std::map<std::string, double> residentByMapping() {
    std::map<std::string, double> resident;
    std::ifstream smaps("/proc/self/smaps");
    std::string line, name = "[anon]";
    while (std::getline(smaps, line)) {
        // A mapping's header: "start-end perms offset dev inode [path]"; its fields: "Key:   value kB".
        const auto colon = line.find(':');
        const auto space = line.find(' ');
        if (space != std::string::npos && (colon == std::string::npos || colon > space)) {
            std::istringstream header(line);
            std::string range, perms, offset, dev, inode, path;
            header >> range >> perms >> offset >> dev >> inode;
            std::getline(header >> std::ws, path);
            name = path.empty() ? anonymousKind(range, perms) : path;
        } else if (line.compare(0, 4, "Rss:") == 0) {
            resident[name] += std::stod(line.substr(4)) / 1024.0;
        }
    }
    return resident;
}

}  // namespace avatarbooth
