// A CUPS scheduler of a test's own (Debian cups-daemon) with a PDF printer (printer-driver-cups-pdf): its
// configuration, spool, logs and socket under the test's scratch folder, CUPS_SERVER pointing libcups (and the
// operator's commands run through `command`) at it. cupsd and the cups-pdf backend need root; `missing()` says
// why a test must skip. Used by the printed card's tests (tests/integration/print_card_test.cpp) and the kiosk's
// (tests/e2e/kiosk_sim_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <cups/cups.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

namespace avatarbooth::test {

namespace fs = std::filesystem;

struct Ran {
    int status = -1;
    std::string out;
};
Ran run(const std::string& command, bool withErrors = true) {
    Ran r;
    FILE* pipe = popen((command + (withErrors ? " 2>&1" : " 2>/dev/null")).c_str(), "r");
    if (!pipe) return r;
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe)) r.out += buffer;
    r.status = pclose(pipe);
    return r;
}
bool have(const std::string& tool) { return run("command -v " + tool + " >/dev/null").status == 0; }

// One cupsd of the test's own with a cups-pdf queue whose PDFs land in `out` (the test's scratch folder). The
// scheduler's configuration, spool, logs and socket go to a fresh folder under /tmp (removed at the end): its
// filters run as the lp user, who can reach /tmp but not necessarily the build tree.
class CupsServer {
public:
    static std::string missing() {
        if (geteuid() != 0) return "cupsd and the cups-pdf backend need root";
        for (const char* f : {"/usr/sbin/cupsd", "/usr/lib/cups/backend/cups-pdf", "/usr/sbin/lpadmin",
                              "/usr/sbin/cupsdisable", "/usr/share/ppd/cups-pdf/CUPS-PDF_opt.ppd"})
            if (!fs::exists(f)) return std::string(f) + " is missing (cups-daemon, cups-client, printer-driver-cups-pdf)";
        for (const char* tool : {"pdfinfo", "pdftoppm", "pdftotext", "zbarimg"})
            if (!have(tool)) return std::string(tool) + " is missing (poppler-utils, zbar-tools)";
        return {};
    }

    explicit CupsServer(const fs::path& out) : out_(out), queue_("avatarbooth-test-" + std::to_string(getpid())) {
        char folder[] = "/tmp/avatarbooth-cups-XXXXXX";
        if (!mkdtemp(folder)) return;
        dir_ = folder;
        const fs::path& dir = dir_;
        fs::permissions(dir, fs::perms::owner_all | fs::perms::group_exec | fs::perms::others_exec);
        fs::create_directories(out);
        for (const char* sub : {"spool", "tmp", "state", "cache", "logs"}) fs::create_directories(dir / sub);
        fs::permissions(dir / "tmp", fs::perms::all | fs::perms::sticky_bit);
        socket_ = dir / "cups.sock";
        std::ofstream(dir / "cupsd.conf") << "Listen " << socket_.string() << "\nLogLevel info\nWebInterface No\n"
                                          << "Browsing No\nDefaultAuthType None\nMaxJobs 50\n"
                                          << "<Location />\n  Order allow,deny\n  Allow all\n</Location>\n"
                                          << "<Policy default>\n  <Limit All>\n    Order deny,allow\n  </Limit>\n"
                                          << "</Policy>\n";
        std::ofstream(dir / "cups-files.conf")
            << "ServerRoot " << dir.string() << "\nRequestRoot " << (dir / "spool").string() << "\nTempDir "
            << (dir / "tmp").string() << "\nStateDir " << (dir / "state").string() << "\nCacheDir "
            << (dir / "cache").string() << "\nServerBin /usr/lib/cups\nDataDir /usr/share/cups\nAccessLog "
            << (dir / "logs/access_log").string() << "\nErrorLog " << (dir / "logs/error_log").string()
            << "\nPageLog " << (dir / "logs/page_log").string() << "\nPrintcap " << (dir / "printcap").string()
            << "\nSystemGroup root\nUser lp\nGroup lp\n";
        // cups-pdf reads the configuration of the queue whose device URI is cups-pdf:/NAME from
        // /etc/cups/cups-pdf-NAME.conf (a path built into the backend): one file per test run, removed at the end.
        pdfConf_ = "/etc/cups/cups-pdf-" + queue_ + ".conf";
        std::ofstream(pdfConf_) << "Out " << out.string() << "\nAnonDirName " << out.string()
                                << "\nLabel 0\nGrp root\nLog " << (dir / "logs").string() << "\n";
        pid_ = fork();
        if (pid_ == 0) {
            execl("/usr/sbin/cupsd", "cupsd", "-f", "-c", (dir / "cupsd.conf").c_str(), "-s",
                  (dir / "cups-files.conf").c_str(), static_cast<char*>(nullptr));
            _exit(127);
        }
        setenv("CUPS_SERVER", socket_.c_str(), 1);
        cupsSetServer(nullptr);  // libcups keeps the server per thread: read CUPS_SERVER again on this one
        for (int i = 0; i < 100 && !fs::exists(socket_); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
        ok_ = fs::exists(socket_) &&
              lpadmin("-p " + queue_ + " -E -v cups-pdf:/" + queue_ + " -P /usr/share/ppd/cups-pdf/CUPS-PDF_opt.ppd");
    }
    ~CupsServer() {
        if (pid_ > 0) {
            kill(pid_, SIGTERM);
            waitpid(pid_, nullptr, 0);
        }
        std::error_code ec;
        fs::remove(pdfConf_, ec);
        if (!dir_.empty()) fs::remove_all(dir_, ec);
        unsetenv("CUPS_SERVER");
        cupsSetServer(nullptr);
    }
    bool ok() const { return ok_; }
    std::string log() const { return run("tail -20 '" + (dir_ / "logs/error_log").string() + "'").out; }
    const std::string& queue() const { return queue_; }
    const fs::path& out() const { return out_; }
    // An operator's command against this server (cupsdisable, cupsreject, lpadmin, lp).
    bool command(const std::string& line) const { return output(line).status == 0; }
    Ran output(const std::string& line) const { return run("CUPS_SERVER='" + socket_.string() + "' " + line); }
    bool lpadmin(const std::string& args) const { return command("/usr/sbin/lpadmin " + args); }

private:
    fs::path out_, dir_, socket_;
    std::string queue_, pdfConf_;
    pid_t pid_ = -1;
    bool ok_ = false;
};

#define REQUIRE_CUPS()                                                                           \
    do {                                                                                         \
        if (const std::string why = ::avatarbooth::test::CupsServer::missing(); !why.empty())                       \
            GTEST_SKIP() << "no real CUPS for this test: " << why << " (tests/setup.sh installs the packages; run as root)"; \
    } while (0)

}  // namespace avatarbooth::test
