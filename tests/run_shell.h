// Runs a shell command line for the tests: its exit code and what it printed.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace avatarbooth::test {

struct CommandResult {
    int exitCode = -1;
    std::string output;  // stdout, and stderr too unless it was kept apart
    std::string errors;  // stderr, when kept apart (runAvatarboothSplit)
};

// A shell command line (`sh -c`): its exit code and what reached stdout.
inline CommandResult runShell(const std::string& command) {
    CommandResult r;
    FILE* pipe = popen(command.c_str(), "r");
    if (pipe == nullptr) return r;
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), buf.size(), pipe)) r.output += buf.data();
    const int status = pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

}  // namespace avatarbooth::test
