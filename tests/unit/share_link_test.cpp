// The visitor's page links (booth/share_link.h): tokens are 128 kernel-random bits in a fixed shape, listen
// addresses and URLs are read and built as the README says, and [share] in booth.toml is checked like every table.
#include "booth/share_link.h"
#include "config/booth_config.h"

#include "config_error_of.h"

#include <gtest/gtest.h>

#include <array>
#include <set>

using namespace avatarbooth;
using avatarbooth::test::errorOf;

TEST(ShareToken, HasTheShapeAndIsNeverRepeated) {
    std::set<std::string> seen;
    for (int i = 0; i < 2000; ++i) {
        const std::string t = makeShareToken();
        ASSERT_EQ(t.size(), 32u) << t;
        ASSERT_TRUE(isShareToken(t)) << t;
        ASSERT_TRUE(seen.insert(t).second) << "token drawn twice: " << t;
    }
}

// Every one of the 128 bits is a fair coin: over 4000 tokens each bit is set 2000 +- 250 times (more than 7.9
// standard deviations: a kernel source never fails this, a constant, counter or clock-seeded byte always does), and
// the hex digits are evenly spread (chi-square, 15 degrees of freedom, far beyond its 99.99th percentile of 44).
TEST(ShareToken, BitsAreUniform) {
    constexpr int kTokens = 4000;
    std::array<int, 128> ones{};
    std::array<int, 16> digits{};
    for (int i = 0; i < kTokens; ++i) {
        const std::string t = makeShareToken();
        for (int d = 0; d < 32; ++d) {
            const int v = t[static_cast<std::size_t>(d)] <= '9' ? t[static_cast<std::size_t>(d)] - '0'
                                                                 : t[static_cast<std::size_t>(d)] - 'a' + 10;
            ++digits[static_cast<std::size_t>(v)];
            for (int b = 0; b < 4; ++b) ones[static_cast<std::size_t>(d * 4 + b)] += (v >> b) & 1;
        }
    }
    for (int b = 0; b < 128; ++b) EXPECT_NEAR(ones[static_cast<std::size_t>(b)], kTokens / 2, 250) << "bit " << b;
    const double expected = kTokens * 32.0 / 16.0;
    double chi2 = 0.0;
    for (const int n : digits) chi2 += (n - expected) * (n - expected) / expected;
    EXPECT_LT(chi2, 44.0);
}

TEST(ShareToken, ShapeCheckRefusesEverythingElse) {
    EXPECT_TRUE(isShareToken("0123456789abcdef0123456789abcdef"));
    EXPECT_FALSE(isShareToken(""));
    EXPECT_FALSE(isShareToken("0123456789abcdef0123456789abcde"));     // 31
    EXPECT_FALSE(isShareToken("0123456789abcdef0123456789abcdef0"));   // 33
    EXPECT_FALSE(isShareToken("0123456789ABCDEF0123456789abcdef"));    // upper case
    EXPECT_FALSE(isShareToken("0123456789abcdef0123456789abcdeg"));
    EXPECT_FALSE(isShareToken("../../../../../../../../etc/passw"));
    EXPECT_FALSE(isShareToken(std::string("0123456789abcdef0123456789abcde\0", 32)));
}

TEST(ShareLink, ListenAddresses) {
    const auto a = parseListenAddress("10.42.0.1:80");
    ASSERT_TRUE(a);
    EXPECT_EQ(a->host, "10.42.0.1");
    EXPECT_EQ(a->port, 80);
    const auto v6 = parseListenAddress("[::1]:8443");
    ASSERT_TRUE(v6);
    EXPECT_EQ(v6->host, "::1");
    EXPECT_EQ(v6->port, 8443);
    for (const char* bad : {"", "10.42.0.1", "10.42.0.1:", ":80", "10.42.0.1:0", "10.42.0.1:65536", "10.42.0.1:8x",
                            "::1:80", "[::1:80", "a b:80", "host/x:80"})
        EXPECT_FALSE(parseListenAddress(bad)) << bad;
    EXPECT_FALSE(parseListenAddress("127.0.0.1:0"));
    EXPECT_TRUE(parseListenAddress("127.0.0.1:0", /*anyPort=*/true));
}

TEST(ShareLink, UrlsFromTheBaseOrTheListenAddress) {
    ShareSettings s;
    const std::string token(32, 'a');
    EXPECT_EQ(sharePageUrl(s, token), "http://10.42.0.1/s/" + token);
    s.listen = "10.42.0.1:8080";
    EXPECT_EQ(shareBaseUrl(s), "http://10.42.0.1:8080");
    s.listen = "[fd00::1]:443";
    s.tlsCertificate = "c.pem";
    EXPECT_EQ(shareBaseUrl(s), "https://[fd00::1]");
    s.baseUrl = "https://booth.example/";
    EXPECT_EQ(sharePageUrl(s, token), "https://booth.example/s/" + token);
}

TEST(ShareConfig, OffByDefaultAndReadFromTheFile) {
    const BoothConfig defaults;
    EXPECT_FALSE(defaults.share.enabled);
    EXPECT_FALSE(defaults.share.offerPhotos);
    const BoothConfig c = parseBoothConfig("[share]\nenabled = true\nlisten = \"127.0.0.1:8080\"\n"
                                           "base_url = \"http://booth.local\"\npage_lifetime_days = 2\nphotos = true\n"
                                           "workers = 4\nread_timeout_s = 3\n",
                                           "booth.toml");
    EXPECT_TRUE(c.share.enabled);
    EXPECT_EQ(c.share.listen, "127.0.0.1:8080");
    EXPECT_EQ(c.share.baseUrl, "http://booth.local");
    EXPECT_EQ(c.share.pageLifetime, std::chrono::hours(48));
    EXPECT_TRUE(c.share.offerPhotos);
    EXPECT_EQ(c.share.workers, 4);
    EXPECT_EQ(c.share.readTimeout, std::chrono::seconds(3));
}

TEST(ShareConfig, MistakesNameFileLineAndKey) {
    EXPECT_EQ(errorOf("[share]\nenabled = \"yes\"\n"), "booth.toml:2: share.enabled: expected true or false");
    EXPECT_EQ(errorOf("[share]\n\nlisten = \"10.42.0.1\"\n"),
              "booth.toml:3: share.listen: \"10.42.0.1\" is not ADDRESS:PORT (port 1-65535)");
    EXPECT_EQ(errorOf("[share]\nbase_url = \"booth.local\"\n"),
              "booth.toml:2: share.base_url: \"booth.local\" is not an http:// or https:// URL without query");
    EXPECT_EQ(errorOf("[share]\nbase_url = \"http://" + std::string(100, 'b') + "\"\n"),
              "booth.toml:2: share.base_url: longer than 100 characters (the QR code would be too dense)");
    EXPECT_EQ(errorOf("[share]\nworkers = 0\n"), "booth.toml:2: share.workers: must be between 1 and 64, got 0");
    EXPECT_EQ(errorOf("[share]\ntls_certificate = \"/etc/ssl/booth.pem\"\n"),
              "booth.toml:2: share.tls_certificate: give both tls_certificate and tls_key, or neither");
    // A page never outlives its session: refused when sharing is on.
    EXPECT_EQ(errorOf("[sessions]\nsession_retention_days = 3\n[share]\nenabled = true\npage_lifetime_days = 10\n"),
              "booth.toml:5: share.page_lifetime_days: a page cannot outlive its session: longer than [sessions] "
              "session_retention_days");
    EXPECT_EQ(errorOf("[sessions]\nsession_retention_days = 3\n[share]\nenabled = true\npage_lifetime_days = 2\n"), "");
}
