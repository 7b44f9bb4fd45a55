// Runs the built avatarbooth executable as a user would, for the end-to-end tests.
#pragma once

#include "run_shell.h"
#include "test_paths.h"

#include <fstream>
#include <iterator>
#include <string>

namespace avatarbooth::test {

// `avatarbooth ARGS REDIRECT` through the shell: its exit code and what reached stdout.
inline CommandResult runWithRedirect(const std::string& args, const std::string& redirect) {
    return runShell(binary().string() + " " + args + " " + redirect);
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
