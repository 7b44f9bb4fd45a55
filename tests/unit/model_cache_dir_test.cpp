// Where the booth keeps its model caches: systemd's CacheDirectory= for the service, the package's folder for its
// user, the XDG cache folder else.
#include "fit/face/model_cache.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <optional>
#include <string>

using namespace avatarbooth;

namespace {

// Puts an environment variable back as it was.
class RestoredEnv {
public:
    explicit RestoredEnv(const char* name) : name_(name) {
        if (const char* v = std::getenv(name)) value_ = v;
    }
    ~RestoredEnv() {
        if (value_) ::setenv(name_, value_->c_str(), 1);
        else ::unsetenv(name_);
    }
    RestoredEnv(const RestoredEnv&) = delete;
    RestoredEnv& operator=(const RestoredEnv&) = delete;

private:
    const char* name_;
    std::optional<std::string> value_;
};

}  // namespace

TEST(ModelCacheDir, SystemdsCacheDirectoryThenXdgCacheHomeThenHome) {
    struct stat st {};
    if (::stat("/var/cache/avatarbooth", &st) == 0 && st.st_uid == ::geteuid())
        GTEST_SKIP() << "/var/cache/avatarbooth is this user's: the booth's cache, whatever the environment says";
    const RestoredEnv cache("CACHE_DIRECTORY"), xdg("XDG_CACHE_HOME"), home("HOME");
    ::setenv("CACHE_DIRECTORY", "/var/cache/avatarbooth:/var/cache/other", 1);
    ::setenv("XDG_CACHE_HOME", "/home/op/.xdg-cache", 1);
    ::setenv("HOME", "/home/op", 1);
    EXPECT_EQ(defaultModelCacheDir(), "/var/cache/avatarbooth");
    ::unsetenv("CACHE_DIRECTORY");
    EXPECT_EQ(defaultModelCacheDir(), "/home/op/.xdg-cache/avatarbooth");
    ::setenv("XDG_CACHE_HOME", "relative/cache", 1);  // the XDG specification: ignored
    EXPECT_EQ(defaultModelCacheDir(), "/home/op/.cache/avatarbooth");
    ::unsetenv("XDG_CACHE_HOME");
    EXPECT_EQ(defaultModelCacheDir(), "/home/op/.cache/avatarbooth");
    ::unsetenv("HOME");
    EXPECT_EQ(defaultModelCacheDir(), "");
}
