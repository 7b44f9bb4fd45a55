// Runs the built avatarbooth executable as a user would, for the end-to-end tests.
#pragma once

#include "test_paths.h"

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

namespace avatarbooth::test {

struct CommandResult {
    int exitCode = -1;
    std::string output;  // stdout, and stderr too unless it was kept apart
    std::string errors;  // stderr, when kept apart (runAvatarboothSplit)
};

// `avatarbooth ARGS REDIRECT` through the shell: its exit code and what reached stdout.
inline CommandResult runWithRedirect(const std::string& args, const std::string& redirect) {
    CommandResult r;
    FILE* pipe = popen((binary().string() + " " + args + " " + redirect).c_str(), "r");
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), buf.size(), pipe)) r.output += buf.data();
    const int status = pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

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

// `avatarbooth ARGS`, its exit code and everything it printed.
inline CommandResult runAvatarbooth(const std::string& args) { return runWithRedirect(args, "2>&1"); }

// `avatarbooth ARGS` with stderr kept apart from stdout (for output a script parses, e.g. --json), through a file
// in DIR.
inline CommandResult runAvatarboothSplit(const std::string& args, const std::filesystem::path& dir) {
    const std::filesystem::path errFile = dir / "stderr.txt";
    CommandResult r = runWithRedirect(args, "2>" + errFile.string());
    std::ifstream in(errFile);
    r.errors.assign(std::istreambuf_iterator<char>(in), {});
    return r;
}

}  // namespace avatarbooth::test
