// Runs the built avatarbooth executable as a user would, for the end-to-end tests.
#pragma once

#include "test_paths.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace avatarbooth::test {

struct CommandResult {
    int exitCode = -1;
    std::string output;  // stdout and stderr
};

// `avatarbooth ARGS`, its exit code and everything it printed.
inline CommandResult runAvatarbooth(const std::string& args) {
    CommandResult r;
    FILE* pipe = popen((binary().string() + " " + args + " 2>&1").c_str(), "r");
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), buf.size(), pipe)) r.output += buf.data();
    const int status = pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

}  // namespace avatarbooth::test
