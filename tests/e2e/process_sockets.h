// The internet sockets a process holds open to the network, read from the kernel's tables (/proc/PID/net/tcp, tcp6,
// udp, udp6) through the process's own file descriptors: how the tests see what a booth process listens on.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace avatarbooth::test {

// "tcp 0100007F:1F90" for each TCP socket of `pid` in the LISTEN state and each bound UDP socket (the local address
// and port in hex, as the kernel writes them).
inline std::vector<std::string> listeningSockets(pid_t pid) {
    namespace fs = std::filesystem;
    std::set<std::string> inodes;
    const fs::path fds = "/proc/" + std::to_string(pid) + "/fd";
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fds, ec)) {
        const std::string target = fs::read_symlink(e.path(), ec).string();
        if (target.rfind("socket:[", 0) == 0) inodes.insert(target.substr(8, target.size() - 9));
    }
    std::vector<std::string> out;
    for (const std::string table : {"tcp", "tcp6", "udp", "udp6"}) {
        std::ifstream in("/proc/" + std::to_string(pid) + "/net/" + table);
        std::string line;
        std::getline(in, line);  // the header
        while (std::getline(in, line)) {
            std::istringstream f(line);
            std::string sl, local, remote, state, queues, timer, retransmits, uid, timeout, inode;
            f >> sl >> local >> remote >> state >> queues >> timer >> retransmits >> uid >> timeout >> inode;
            const bool listening = table.rfind("tcp", 0) == 0 ? state == "0A" : true;
            if (listening && inodes.count(inode)) out.push_back(table.substr(0, 3) + " " + local);
        }
    }
    return out;
}

}  // namespace avatarbooth::test
