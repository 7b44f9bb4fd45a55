// libFuzzer target: the visitor's page server's request handling (share/share_site.h) as `avatarbooth share` runs
// it: the request target percent-decoded by cpp-httplib's own decoder (what the server hands over as the path),
// then answered by ShareSite over a sessions folder holding one fresh session (with photos) and one expired one.
//
// Input layout: one byte picks the method (GET, HEAD, POST, another word), the rest is the raw request target. The
// target traps unless every answer keeps share_site.h's promises: 200, 404 or 405 only; every 404 the one
// not-found answer, byte for byte; 405 for every method but GET and HEAD; a 200 only for the white list's paths of
// the fresh session's token (never the expired one's, never a photo, which this site does not offer, never a file
// outside the session), carrying that file's own bytes.
#include "fuzz_files.h"

#include "booth/share_link.h"
#include "share/share_site.h"

#include <httplib.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

namespace {

using namespace avatarbooth;
namespace fs = std::filesystem;

const std::string kFresh(32, 'a');
const std::string kExpired(32, 'b');
const std::map<std::string, std::string> kFiles = {{"avatar.glb", "GLB"}, {"avatar.usdz", "USDZ"},
                                                   {"preview_three_quarter.png", "PNG"}, {"front.jpg", "FRONT"},
                                                   {"side.jpg", "SIDE"}, {"fit.json", "{}"}};

struct World {
    fuzz::ScratchDir dir{"share_request"};
    std::unique_ptr<ShareSite> site;
    WallTime now = WallTime(std::chrono::hours(24 * 20000));
    World() {
        const fs::path sessions = dir.path() / "sessions";
        for (const auto& [code, token, keptDaysAgo] : {std::tuple{"AAAAAA", kFresh, 1}, std::tuple{"BBBBBB", kExpired, 9}}) {
            fs::create_directories(sessions / code);
            const auto kept = std::chrono::duration_cast<std::chrono::seconds>(
                (now - std::chrono::hours(24 * keptDaysAgo)).time_since_epoch()).count();
            fuzz::writeBytes(sessions / code / "session.json", "{\"code\": \"" + std::string(code) + "\", \"kept_at\": " +
                                                                   std::to_string(kept) + ", \"share_token\": \"" + token + "\"}");
            for (const auto& [name, bytes] : kFiles) fuzz::writeBytes(sessions / code / name, bytes);
        }
        fuzz::writeBytes(dir.path() / "outside.txt", "OUTSIDE");
        fuzz::writeBytes(dir.path() / "model-viewer.js", "JS");
        ShareSettings share;
        share.enabled = true;
        SessionStoreSettings store;
        store.directory = sessions;
        site = std::make_unique<ShareSite>(share, store, dir.path() / "model-viewer.js");
    }
};

void check(bool ok) {
    if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static World world;
    if (size < 1) return 0;
    static const char* const kMethods[] = {"GET", "HEAD", "POST", "PUT", "DELETE", "OPTIONS", "get", "BREW"};
    const std::string method = kMethods[data[0] % 8];
    const std::string target(reinterpret_cast<const char*>(data + 1), size - 1);
    // What httplib's server does with the target: the part before '?' percent-decoded.
    const std::string path = httplib::detail::decode_url(target.substr(0, target.find('?')), false);
    const ShareResponse r = world.site->answer(method, path, world.now);
    if (method != "GET" && method != "HEAD") {
        check(r.status == 405);
        return 0;
    }
    check(r.status == 200 || r.status == 404);
    if (r.status == 404) {
        check(r.body == ShareSite::notFound().body);
        return 0;
    }
    if (path == "/static/model-viewer.js") return check(r.body == "JS"), 0;
    if (path == "/static/page.css") return 0;
    const std::string base = "/s/" + kFresh;
    check(path.rfind(base, 0) == 0);
    const std::string rest = path.substr(base.size());
    if (rest.empty()) return check(r.contentType.rfind("text/html", 0) == 0), 0;
    if (rest == "/avatar.glb") return check(r.body == "GLB"), 0;
    if (rest == "/avatar.usdz") return check(r.body == "USDZ"), 0;
    if (rest == "/preview.png") return check(r.body == "PNG"), 0;
    check(false);  // a 200 for anything else
    return 0;
}
