// `avatarbooth share`'s server (app/share/) on a real socket on loopback: a kept session's token serves its page,
// glb and usdz; every kind of miss (unknown, malformed, expired token; traversal and encoding tricks; another
// session's photos) gets the identical 404; POST gets 405; an oversized header is refused; 200 clients at once are
// answered or turned away without harm; a silent client is cut off after the read timeout.
#include "booth/session_store.h"
#include "booth/share_link.h"
#include "common/atomic_output.h"
#include "share/share_server.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <httplib.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <thread>

using namespace avatarbooth;
namespace fs = std::filesystem;

namespace {

// Stand-ins for a session's files: their bytes are checked as served, not parsed.
const std::map<std::string, std::string> kSessionFiles = {
    {"avatar.glb", "glTF\x02\x00\x00\x00 the avatar"},
    {"avatar.usdz", "PK\x03\x04 the usdz"},
    {"preview_three_quarter.png", "\x89PNG the preview"},
    {"front.jpg", "\xff\xd8\xff the front photo"},
    {"side.jpg", "\xff\xd8\xff the side photo"},
    {"landmarks.json", "{}"},
    {"fit.json", "{}"}};

// A session kept through the real store (its session.json, token and modes as the booth writes them).
struct Kept {
    std::string code, token;
    fs::path folder;
};
Kept keepSession(SessionStore& store, WallTime keptAt) {
    const fs::path pending = store.pendingPath();
    {
        StagedDirectory staged(pending, "fit.json");
        for (const auto& [name, bytes] : kSessionFiles) writeFileAtomically(staged.staging() / name, bytes);
        staged.commit();
    }
    Kept k;
    k.code = store.keep(pending, keptAt);
    k.folder = *store.find(k.code);
    k.token = readShareToken(k.folder).value_or("");
    return k;
}

// The raw answer to raw request bytes: what a client that does not play by the rules gets back.
struct RawAnswer {
    int status = 0;  // 0: the connection closed without a status line
    std::string head, body;
};
RawAnswer rawRequest(int port, const std::string& bytes, std::chrono::milliseconds wait = std::chrono::seconds(5)) {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    RawAnswer a;
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        ::close(fd);
        return a;
    }
    timeval tv{static_cast<time_t>(wait.count() / 1000), static_cast<suseconds_t>((wait.count() % 1000) * 1000)};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    std::size_t sent = 0;
    while (sent < bytes.size()) {
        const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
        if (n <= 0) break;  // the server closed on us (a refused header): read what it said
        sent += static_cast<std::size_t>(n);
    }
    std::string all;
    char buffer[8192];
    for (;;) {
        const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
        if (n <= 0) break;
        all.append(buffer, static_cast<std::size_t>(n));
        const std::size_t end = all.find("\r\n\r\n");
        if (end != std::string::npos) {  // a whole answer: head plus Content-Length bytes
            const std::size_t cl = all.find("Content-Length: ");
            if (cl != std::string::npos && cl < end &&
                all.size() >= end + 4 + std::stoul(all.substr(cl + 16)))
                break;
        }
    }
    ::close(fd);
    if (all.rfind("HTTP/1.1 ", 0) == 0) {
        a.status = std::stoi(all.substr(9, 3));
        const std::size_t end = all.find("\r\n\r\n");
        a.head = all.substr(0, end);
        if (end != std::string::npos) a.body = all.substr(end + 4);
    }
    return a;
}

std::string get(const std::string& path) {
    return "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
}

class ShareServerTest : public ::testing::Test {
protected:
    void start(ShareSettings share = {}) {
        dir_ = test::scratchDir(std::string("share_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        sessions_.directory = dir_ / "sessions";
        store_ = std::make_unique<SessionStore>(sessions_);
        const auto now = std::chrono::system_clock::now();
        fresh_ = keepSession(*store_, now - std::chrono::hours(1));
        expired_ = keepSession(*store_, now - share.pageLifetime - std::chrono::minutes(1));
        std::ofstream(dir_ / "model-viewer.js") << "/* model-viewer stand-in */";
        share.enabled = true;
        site_ = std::make_unique<ShareSite>(share, sessions_, dir_ / "model-viewer.js");
        server_ = std::make_unique<ShareServer>(*site_, share);
        port_ = server_->bind("127.0.0.1", 0);
        thread_ = std::thread([this] { server_->run(); });
        // Ready when it answers.
        for (int i = 0; i < 100 && rawRequest(port_, get("/")).status == 0; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    void TearDown() override {
        if (server_) server_->stop();
        if (thread_.joinable()) thread_.join();
    }
    httplib::Client client() {
        httplib::Client c("127.0.0.1", port_);
        c.set_connection_timeout(std::chrono::seconds(10));
        c.set_read_timeout(std::chrono::seconds(10));
        return c;
    }

    fs::path dir_;
    SessionStoreSettings sessions_;
    std::unique_ptr<SessionStore> store_;
    Kept fresh_, expired_;
    std::unique_ptr<ShareSite> site_;
    std::unique_ptr<ShareServer> server_;
    std::thread thread_;
    int port_ = 0;
};

}  // namespace

TEST_F(ShareServerTest, GoodTokenServesThePageGlbAndUsdz) {
    start();
    ASSERT_TRUE(isShareToken(fresh_.token)) << "session.json has no share_token";
    auto c = client();
    const auto page = c.Get("/s/" + fresh_.token);
    ASSERT_TRUE(page) << httplib::to_string(page.error());
    EXPECT_EQ(page->status, 200);
    EXPECT_EQ(page->get_header_value("Content-Type"), "text/html; charset=utf-8");
    const std::string& html = page->body;
    const std::string base = "/s/" + fresh_.token + "/";
    EXPECT_NE(html.find("<model-viewer src=\"" + base + "avatar.glb\" ios-src=\"" + base + "avatar.usdz\""),
              std::string::npos) << html;
    EXPECT_NE(html.find("ar ar-modes=\"scene-viewer quick-look\""), std::string::npos);
    EXPECT_NE(html.find("<script src=\"/static/model-viewer.js\"></script>"), std::string::npos);
    EXPECT_NE(html.find("name=\"viewport\""), std::string::npos);
    EXPECT_EQ(html.find("http://"), std::string::npos) << "the page loads nothing from elsewhere";
    EXPECT_EQ(html.find("https://"), std::string::npos) << "the page loads nothing from elsewhere";
    EXPECT_EQ(html.find("front.jpg"), std::string::npos) << "photos are not offered by default";
    // The security headers.
    EXPECT_EQ(page->get_header_value("Content-Security-Policy").rfind("default-src 'self';", 0), 0u);
    EXPECT_EQ(page->get_header_value("Referrer-Policy"), "no-referrer");
    EXPECT_EQ(page->get_header_value("X-Content-Type-Options"), "nosniff");
    EXPECT_EQ(page->get_header_value("Cache-Control"), "no-store");
    // The files, byte for byte, with their types.
    for (const auto& [name, type, onDisk] :
         {std::tuple{"avatar.glb", "model/gltf-binary", "avatar.glb"},
          std::tuple{"avatar.usdz", "model/vnd.usdz+zip", "avatar.usdz"},
          std::tuple{"preview.png", "image/png", "preview_three_quarter.png"}}) {
        const auto r = c.Get(base + name);
        ASSERT_TRUE(r) << name;
        EXPECT_EQ(r->status, 200) << name;
        EXPECT_EQ(r->get_header_value("Content-Type"), type) << name;
        EXPECT_EQ(r->body, kSessionFiles.at(onDisk)) << name;
    }
    EXPECT_EQ(c.Get("/static/model-viewer.js")->body, "/* model-viewer stand-in */");
    // HEAD: the same head, no body.
    const auto head = c.Head(base + "avatar.glb");
    ASSERT_TRUE(head);
    EXPECT_EQ(head->status, 200);
    EXPECT_TRUE(head->body.empty());
    EXPECT_EQ(head->get_header_value("Content-Length"), std::to_string(kSessionFiles.at("avatar.glb").size()));
}

TEST_F(ShareServerTest, EveryMissAnswersTheSame) {
    start();
    const RawAnswer reference = rawRequest(port_, get("/s/" + std::string(32, '0')));
    ASSERT_EQ(reference.status, 404);
    ASSERT_FALSE(reference.body.empty());
    const std::string t = fresh_.token;
    const std::vector<std::string> misses = {
        "/", "/s/", "/s", "/index.html", "/robots.txt", "/static/", "/static/../README.md",
        "/s/" + expired_.token,                              // expired
        "/s/" + expired_.token + "/avatar.glb",
        "/s/" + t.substr(0, 31),                             // malformed: short, long, upper case, not hex
        "/s/" + t + "0",
        "/s/" + std::string(32, 'A'),
        "/s/" + std::string(31, 'a') + "g",
        "/s/" + t + "/front.jpg",                            // photos: not allowed by default
        "/s/" + t + "/side.jpg",
        "/s/" + t + "/fit.json",                             // a file of the session that is not public
        "/s/" + t + "/landmarks.json",
        "/s/" + t + "/session.json",
        "/s/" + t + "/preview_three_quarter.png",
        "/s/" + t + "/../" + expired_.token,                 // traversal, plain and encoded
        "/s/" + t + "/../../../../etc/passwd",
        "/s/" + t + "/%2e%2e/%2e%2e/etc/passwd",
        "/s/" + t + "/..%2f..%2fetc%2fpasswd",
        "/s/" + t + "%2f..%2f" + expired_.token,
        "/s/" + t + "/%2e%2e%2f" + fresh_.code + "%2ffit.json",
        "/s/" + t + "/avatar.glb%00.png",                    // NUL
        "/s/" + t + "%00",
        "/s/" + t + "/",                                     // one URL per thing
        "/s/" + t + "/avatar.glb/",
        "/s/" + t + "//avatar.glb",
        "/s/" + t + "/./avatar.glb",
        "/s/" + t + "/AVATAR.GLB",
        "//etc/passwd",
        "/%2e%2e/%2e%2e/etc/passwd",
        "/s/" + fresh_.code,                                 // the short code is not a key to the page
        "/" + fresh_.code + "/avatar.glb",
        "/sessions/" + fresh_.code + "/front.jpg",
        "/s/" + t + "/..\\..\\fit.json",
        "/s/%2e%2e%2f%2e%2e%2f%2e%2e%2f%2e%2e%2f%2e%2e%2f%2e%2e%2f",
    };
    int identical = 0;
    for (const std::string& path : misses) {
        const RawAnswer a = rawRequest(port_, get(path));
        EXPECT_EQ(a.status, 404) << path;
        EXPECT_EQ(a.body, reference.body) << path;
        identical += a.status == 404 && a.body == reference.body;
    }
    // An absolute URI and a bare "*" as the target: no path at all.
    for (const std::string& target : {std::string("http://127.0.0.1/etc/passwd"), std::string("/etc/passwd")}) {
        const RawAnswer a = rawRequest(port_, get(target));
        EXPECT_NE(a.status, 200) << target;
        EXPECT_EQ(a.body.find("root:"), std::string::npos) << target;
    }
    std::printf("[ figures ] misses answered with the identical 404: %d of %zu\n", identical, misses.size());
    // The good token still works after all that.
    EXPECT_EQ(rawRequest(port_, get("/s/" + t)).status, 200);
}

TEST_F(ShareServerTest, PhotosOnlyWhenTheOperatorAllows) {
    ShareSettings share;
    share.offerPhotos = true;
    start(share);
    const RawAnswer page = rawRequest(port_, get("/s/" + fresh_.token));
    EXPECT_NE(page.body.find("/s/" + fresh_.token + "/front.jpg"), std::string::npos);
    const RawAnswer photo = rawRequest(port_, get("/s/" + fresh_.token + "/front.jpg"));
    EXPECT_EQ(photo.status, 200);
    EXPECT_EQ(photo.body, kSessionFiles.at("front.jpg"));
    EXPECT_NE(photo.head.find("Content-Disposition: attachment"), std::string::npos);
    // Once retention has deleted the photo it is a miss like any other.
    fs::remove(fresh_.folder / "front.jpg");
    EXPECT_EQ(rawRequest(port_, get("/s/" + fresh_.token + "/front.jpg")).status, 404);
}

TEST_F(ShareServerTest, OnlyGetAndHead) {
    start();
    auto c = client();
    for (const std::string& path : {"/s/" + fresh_.token, "/s/" + std::string(32, '0'), std::string("/")}) {
        const auto post = c.Post(path, "x=1", "application/x-www-form-urlencoded");
        ASSERT_TRUE(post) << path;
        EXPECT_EQ(post->status, 405) << path;
        EXPECT_EQ(post->get_header_value("Allow"), "GET, HEAD");
        const auto del = c.Delete(path);
        ASSERT_TRUE(del);
        EXPECT_EQ(del->status, 405);
    }
    // A method httplib does not know at all, and a GET that carries a body.
    EXPECT_EQ(rawRequest(port_, "BREW /s/" + fresh_.token + " HTTP/1.1\r\nHost: x\r\n\r\n").status, 400);
    EXPECT_EQ(rawRequest(port_, "GET /s/" + fresh_.token + " HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\n\r\nhello").status,
              413);
    EXPECT_EQ(fs::exists(fresh_.folder / "avatar.glb"), true) << "nothing was changed";
}

TEST_F(ShareServerTest, OversizedRequestsAreRefused) {
    start();
    const std::string page = "/s/" + fresh_.token;
    // One header line of 64 KiB; 80 small headers (over the server's 64: its own 431); 200 small headers (newer
    // cpp-httplib, trixie's 0.18, refuses more than 100 itself with a 400 before the server sees them); a 20 KiB
    // request line.
    const RawAnswer longHeader =
        rawRequest(port_, "GET " + page + " HTTP/1.1\r\nHost: x\r\nX-Big: " + std::string(64 * 1024, 'a') + "\r\n\r\n");
    EXPECT_NE(longHeader.status, 200) << longHeader.head;
    const auto headers = [&](int n) {
        std::string many = "GET " + page + " HTTP/1.1\r\nHost: x\r\n";
        for (int i = 0; i < n; ++i) many += "X-H" + std::to_string(i) + ": " + std::string(100, 'b') + "\r\n";
        return rawRequest(port_, many + "\r\n");
    };
    const RawAnswer manyHeaders = headers(80);
    EXPECT_EQ(manyHeaders.status, 431) << manyHeaders.head;
    const RawAnswer tooManyHeaders = headers(200);
    EXPECT_TRUE(tooManyHeaders.status == 431 || tooManyHeaders.status == 400) << tooManyHeaders.head;
    const RawAnswer longLine = rawRequest(port_, get(page + "?" + std::string(20 * 1024, 'q')));
    EXPECT_NE(longLine.status, 200) << longLine.head;
    std::printf("[ figures ] 64 KiB header line -> %d, 80 headers -> %d, 200 headers -> %d, 20 KiB request line -> %d "
                "(0: closed)\n",
                longHeader.status, manyHeaders.status, tooManyHeaders.status, longLine.status);
    EXPECT_EQ(rawRequest(port_, get(page)).status, 200) << "still serving";
}

TEST_F(ShareServerTest, TwoHundredClientsAtOnce) {
    ShareSettings share;
    share.workers = 4;
    start(share);
    constexpr int kClients = 200;
    std::atomic<int> ok{0}, refused{0}, wrong{0};
    std::vector<std::thread> clients;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < kClients; ++i)
        clients.emplace_back([&, i] {
            const std::string path = "/s/" + fresh_.token + (i % 2 ? "/avatar.glb" : "");
            const auto c0 = std::chrono::steady_clock::now();
            const RawAnswer a = rawRequest(port_, get(path), std::chrono::seconds(20));
            if (std::getenv("SHARE_TEST_VERBOSE"))
                std::printf("client %d: %d after %.3f s\n", i, a.status, std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count());
            if (a.status == 200 && (i % 2 == 0 || a.body == kSessionFiles.at("avatar.glb"))) ++ok;
            else if (a.status == 0 || a.status == 503) ++refused;
            else ++wrong;
        });
    for (auto& t : clients) t.join();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[ figures ] %d clients at once, 4 workers: %d served, %d turned away, %d wrong, in %.2f s\n", kClients,
                ok.load(), refused.load(), wrong.load(), seconds);
    EXPECT_EQ(wrong.load(), 0);
    EXPECT_EQ(ok.load() + refused.load(), kClients);
    EXPECT_GT(ok.load(), kClients / 2);
    EXPECT_EQ(rawRequest(port_, get("/s/" + fresh_.token)).status, 200) << "still serving";
    EXPECT_EQ(server_->counters().serverErrors, 0u);
}

TEST_F(ShareServerTest, SilentClientIsCutOffAfterTheReadTimeout) {
    ShareSettings share;
    share.readTimeout = std::chrono::seconds(1);
    share.workers = 1;  // the one worker is the one the slow client holds
    start(share);
    const auto t0 = std::chrono::steady_clock::now();
    // Half a request line, then silence: the server closes the connection without an answer.
    const RawAnswer a = rawRequest(port_, "GET /s/" + fresh_.token.substr(0, 8), std::chrono::seconds(10));
    const double held = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[ figures ] a silent client was cut off after %.2f s (read timeout 1 s)\n", held);
    EXPECT_EQ(a.status, 0) << a.head;  // no answer, the connection closed
    EXPECT_GE(held, 0.9);
    EXPECT_LT(held, 3.0);
    // The worker is free again.
    EXPECT_EQ(rawRequest(port_, get("/s/" + fresh_.token)).status, 200);
}

TEST_F(ShareServerTest, PageSizeAndLoadTimeOnLoopback) {
    start();
    auto c = client();
    const auto t0 = std::chrono::steady_clock::now();
    const auto page = c.Get("/s/" + fresh_.token);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_TRUE(page);
    std::printf("[ figures ] the page: %zu bytes of HTML in %.2f ms on loopback\n", page->body.size(), ms);
    EXPECT_LT(page->body.size(), 8192u);
}
