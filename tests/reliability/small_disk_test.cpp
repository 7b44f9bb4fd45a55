// The disk really fills up: `avatarbooth run` (the simulated booth) writes its sessions to a small tmpfs, mounted
// in a user and mount namespace of its own (`unshare -rm`: no root needed). The filesystem is filled until a fit's
// folder no longer fits; the booth must say so and carry on, leave nothing partial, and keep the next session once
// space is freed. Skips with a message where unprivileged user namespaces are not allowed.
#include "reliability_support.h"

#include "test_paths.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <regex>

namespace fs = std::filesystem;
using namespace avatarbooth;
using namespace avatarbooth::reliability;

namespace {

}  // namespace

TEST(SmallDisk, FullFilesystemWhileWritingThenSpaceFreed) {
    if (std::system("unshare -rm true >/dev/null 2>&1") != 0)
        GTEST_SKIP() << "unprivileged user namespaces are not available here (unshare -rm): the small-filesystem test "
                        "is skipped; the injected ENOSPC tests (BoothFaults.DiskFull*) still run";
    const fs::path dir = test::scratchDir("reliability_small_disk");
    const fs::path visitor = syntheticVisitorFolder(fs::path(AVATARBOOTH_TEST_WORK_DIR) / "reliability_visitor");
    const fs::path mnt = dir / "mnt";
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[camera]\nbackend = \"sim\"\nsim_folder = \"" << visitor.string() << "\"\n"
                          << "[buttons]\nbackend = \"sim\"\n"
                          << "[display]\nbackend = \"headless\"\nwidth = 640\nheight = 360\n"
                          << "[screen]\nstrings_file = \"" << AVATARBOOTH_TEST_SOURCE_DIR << "/app/assets/strings.toml\"\n"
                          << "[flow]\ncountdown_s = 1.0\nsteady_s = 0.0\nthanks_time_s = 1.0\nthanks_min_time_s = 0.0\n"
                          << "press_guard_s = 0.1\n"
                          << "[sessions]\ndirectory = \"" << (mnt / "sessions").string() << "\"\n";
    // Inside the namespace: a 16 MB tmpfs filled up to its last 200 kB (less than a fit's folder), the booth
    // started; once it has failed to write a fit, the filler goes (space freed) and the booth must keep the next.
    const fs::path script = dir / "small_disk.sh";
    std::ofstream(script) << R"(set -u
mnt="$1"; bin="$2"; cfg="$3"; out="$4"
mkdir -p "$mnt" && mount -t tmpfs -o size=16m,mode=0700 tmpfs "$mnt" || exit 90
mkdir -p "$mnt/sessions"
avail=$(df --output=avail -k "$mnt" | tail -1)
dd if=/dev/zero of="$mnt/filler" bs=1k count=$((avail - 200)) status=none
EGL_PLATFORM=surfaceless "$bin" run --config "$cfg" --sessions 100 >"$out/daemon.log" 2>&1 &
pid=$!
wait_for() { for _ in $(seq 1 1800); do grep -q "$1" "$out/daemon.log" && return 0; kill -0 $pid 2>/dev/null || return 1; sleep 0.05; done; return 1; }
wait_for "session folder was not written" || { echo "no failed write"; kill -9 $pid; exit 91; }
df -k "$mnt" | tail -1 > "$out/df_full.txt"
date +%s.%N > "$out/freed_at"
rm -f "$mnt/filler"
wait_for "session kept as" || { echo "nothing kept after freeing space"; kill -9 $pid; exit 92; }
date +%s.%N > "$out/kept_at"
kill -TERM $pid; wait $pid; echo $? > "$out/exit_code"
cp -a "$mnt/sessions" "$out/sessions"
)";
    const std::string cmd = "unshare -rm bash '" + script.string() + "' '" + mnt.string() + "' '" +
                            test::binary().string() + "' '" + config.string() + "' '" + dir.string() + "' 2>&1";
    const int rc = std::system(cmd.c_str());
    const std::string log = test::readFileBytes(dir / "daemon.log");
    ASSERT_EQ(rc, 0) << "the namespace script failed (" << rc << "): " << log;
    EXPECT_NE(log.find("No space left on device"), std::string::npos) << log;
    EXPECT_EQ(test::readFileBytes(dir / "exit_code"), "0\n") << log;

    const SessionsCheck c = checkSessions(dir / "sessions");
    for (const auto& p : c.problems) ADD_FAILURE() << p;
    EXPECT_EQ(c.leftovers, 0);
    ASSERT_GE(c.complete.size(), 1u);
    if (haveGltfValidator()) {
        for (const auto& code : c.complete) {
            std::string report;
            EXPECT_TRUE(validateGlb(dir / "sessions" / code / "avatar.glb", &report)) << report;
        }
    }
    const double freed = std::stod(test::readFileBytes(dir / "freed_at"));
    const double kept = std::stod(test::readFileBytes(dir / "kept_at"));
    std::printf("figure: small filesystem full -> fit refused with ENOSPC, nothing partial; next session kept %.1f s "
                "after space was freed (includes the visitor posing again)\n",
                kept - freed);
}
