// `avatarbooth share` as the unit runs it: with the default configuration it listens nowhere and says why; turned
// on, it listens exactly where it is told (read back from /proc/net/tcp through the process's own sockets), answers,
// and stops on SIGTERM with its counts.
#include "process_sockets.h"
#include "run_binary.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <httplib.h>
#include <openssl/x509_vfy.h>

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

namespace fs = std::filesystem;
using namespace avatarbooth::test;
using namespace std::chrono_literals;

namespace {

}  // namespace

TEST(ShareCli, OffByDefaultListensNowhere) {
    const fs::path dir = scratchDir("share_cli_off");
    std::ofstream(dir / "booth.toml") << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n";
    const auto t0 = std::chrono::steady_clock::now();
    const CommandResult r = runAvatarbooth("share --config " + (dir / "booth.toml").string());
    EXPECT_LT(std::chrono::steady_clock::now() - t0, 5s);
    EXPECT_EQ(r.exitCode, 6) << r.output;  // the bad-config code: a unit started by mistake fails visibly
    EXPECT_NE(r.output.find("sharing is off ([share] enabled = false in " + (dir / "booth.toml").string() +
                            "): nothing listens"),
              std::string::npos)
        << r.output;
}

namespace {

// `avatarbooth share` started on a free loopback port with [share] on and `extra` in its config; the port it
// printed (0 when it printed none within 5 s, the process then killed).
struct ShareProcess {
    pid_t pid = -1;
    int port = 0;
    fs::path log;
};

ShareProcess startShare(const fs::path& dir, const std::string& extra = "") {
    fs::create_directories(dir / "sessions");
    std::ofstream(dir / "booth.toml") << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n"
                                      << "[share]\nenabled = true\nlisten = \"127.0.0.1:1\"\n" << extra;
    ShareProcess p;
    p.log = dir / "log.txt";
    p.pid = fork();
    if (p.pid == 0) {
        const int out = open(p.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(out, 1);
        dup2(out, 2);
        const std::string bin = binary().string(), config = (dir / "booth.toml").string();
        execl(bin.c_str(), bin.c_str(), "share", "--config", config.c_str(), "--listen", "127.0.0.1:0",
              static_cast<char*>(nullptr));
        _exit(127);
    }
    for (int i = 0; i < 250 && p.port == 0 && p.pid > 0; ++i) {
        const std::string text = readFileBytes(p.log);
        const std::size_t at = text.find("listening on 127.0.0.1:");
        if (at != std::string::npos) p.port = std::atoi(text.c_str() + at + 23);
        else std::this_thread::sleep_for(20ms);
    }
    if (p.port == 0 && p.pid > 0) {
        kill(p.pid, SIGKILL);
        waitpid(p.pid, nullptr, 0);
    }
    return p;
}

}  // namespace

TEST(ShareCli, ListensWhereToldAnswersAndStopsOnSigterm) {
    const ShareProcess share = startShare(scratchDir("share_cli_on"));
    const pid_t pid = share.pid;
    const int port = share.port;
    const fs::path& log = share.log;
    ASSERT_GT(port, 0) << readFileBytes(log);
    // Exactly one listening socket, on 127.0.0.1 (7F000001 as the kernel writes it) and the port it printed.
    char expected[32];
    std::snprintf(expected, sizeof expected, "tcp 0100007F:%04X", port);
    EXPECT_EQ(listeningSockets(pid), std::vector<std::string>{expected});
    httplib::Client c("127.0.0.1", port);
    const auto r = c.Get("/s/0123456789abcdef0123456789abcdef");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 404);
    kill(pid, SIGTERM);
    int status = 0;
    bool exited = false;
    for (int i = 0; i < 150 && !exited; ++i) {
        if (waitpid(pid, &status, WNOHANG) == pid) exited = true;
        else std::this_thread::sleep_for(20ms);
    }
    if (!exited) {
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
    }
    EXPECT_TRUE(exited) << "not stopped within 3 s of SIGTERM";
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << readFileBytes(log);
    EXPECT_NE(readFileBytes(log).find("stopped; 0 served, 1 not found"), std::string::npos) << readFileBytes(log);
}

// With the operator's certificate it speaks HTTPS only: a client that trusts that certificate gets the same 404 for
// an unknown token, and plain HTTP on the same port gets no page.
TEST(ShareCli, ServesHttpsWithTheOperatorsCertificate) {
    const fs::path dir = scratchDir("share_cli_tls");
    fs::create_directories(dir);
    const fs::path cert = dir / "booth.crt", key = dir / "booth.key";
    const std::string make = "openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=127.0.0.1 -addext "
                             "subjectAltName=IP:127.0.0.1 -keyout '" + key.string() + "' -out '" + cert.string() +
                             "' >/dev/null 2>&1";
    if (std::system(make.c_str()) != 0) GTEST_SKIP() << "openssl could not make a test certificate";
    const ShareProcess share = startShare(dir, "tls_certificate = \"" + cert.string() + "\"\ntls_key = \"" +
                                                   key.string() + "\"\n");
    ASSERT_GT(share.port, 0) << readFileBytes(share.log);
    EXPECT_NE(readFileBytes(share.log).find("(https)"), std::string::npos) << readFileBytes(share.log);
    httplib::SSLClient tls("127.0.0.1", share.port);
    tls.set_ca_cert_path(cert.c_str());
    tls.enable_server_certificate_verification(true);
    const auto r = tls.Get("/s/0123456789abcdef0123456789abcdef");
    ASSERT_TRUE(r) << httplib::to_string(r.error());
    EXPECT_EQ(r->status, 404);
    EXPECT_EQ(tls.get_openssl_verify_result(), X509_V_OK);
    httplib::Client plain("127.0.0.1", share.port);
    plain.set_read_timeout(3, 0);
    const auto p = plain.Get("/");
    EXPECT_TRUE(!p || p->status == 400) << "plain HTTP on the HTTPS port answered " << p->status;
    kill(share.pid, SIGTERM);
    int status = 0;
    waitpid(share.pid, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << readFileBytes(share.log);
}
