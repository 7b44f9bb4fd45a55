// Helpers of the `kernel` tests: knowing we run inside the qemu guest, loading the guest's modules, sysfs files.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace avatarbooth::kernel_test {

// True inside the guest tests/kernel/run.sh boots (its init sets AVATARBOOTH_KERNEL_GUEST and the kernel command
// line carries avatarbooth_kernel_guest=1). Elsewhere the tests skip: they load modules and create devices.
inline bool inGuest() {
    const char* env = std::getenv("AVATARBOOTH_KERNEL_GUEST");
    if (!env || std::string(env) != "1") return false;
    std::ifstream cmdline("/proc/cmdline");
    std::string line;
    std::getline(cmdline, line);
    return line.find("avatarbooth_kernel_guest=1") != std::string::npos;
}

// Runs a shell command in the guest; its exit status.
inline int run(const std::string& command) {
    const int rc = std::system(command.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128;
}

// Loads a module (with arguments) from the guest's module tree ($KMOD_ROOT); its exit status.
inline int modprobe(const std::string& moduleAndArgs) {
    const char* root = std::getenv("KMOD_ROOT");
    return run(std::string("modprobe ") + (root && *root ? std::string("-d ") + root + " " : "") + moduleAndArgs);
}

inline std::string readFile(const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    std::string text = s.str();
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    return text;
}

// Writes a sysfs/configfs attribute; false when the kernel refused it.
inline bool writeFile(const std::string& path, const std::string& value) {
    std::ofstream out(path);
    out << value;
    out.flush();
    return static_cast<bool>(out);
}

}  // namespace avatarbooth::kernel_test

// Skips the current test (saying why) outside the qemu guest.
#define AVATARBOOTH_REQUIRE_KERNEL_GUEST()                                                                      \
    do {                                                                                                        \
        if (!::avatarbooth::kernel_test::inGuest())                                                             \
            GTEST_SKIP() << "not inside the kernel-test guest: run `ctest -L kernel` (tests/kernel/run.sh boots " \
                            "Debian's kernel under qemu and runs these there)";                                 \
    } while (0)
