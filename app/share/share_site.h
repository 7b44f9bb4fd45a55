// The visitor's page as requests and answers, without sockets: what `avatarbooth share` (share_server.h) serves
// and what the fuzz target feeds (tests/fuzz/fuzz_share_request.cpp).
//
// The whole site, as a white list (anything else is the one "not found" answer):
//   GET /s/<token>                  the page: the avatar turning in <model-viewer>, its AR button, the downloads
//   GET /s/<token>/avatar.glb       the avatar (model-viewer and Android's Scene Viewer load it)
//   GET /s/<token>/avatar.usdz      the avatar for iOS's AR Quick Look
//   GET /s/<token>/preview.png      the three-quarter preview (the viewer's poster; a download)
//   GET /s/<token>/front.jpg|.png, side.jpg|.png   the photos, only when the operator allows it and while kept
//   GET /static/model-viewer.js, /static/page.css  the viewer (vendored from npm) and the page's style
// No path taken from a request ever reaches the file system: the token is 32 hex digits looked up in the
// sessions' index, and the file is one of the names above. An unknown, malformed or expired token, a file the
// session does not have or may not give, and any other path all get the same 404 with the same body. Methods
// other than GET and HEAD get 405 whatever the path (so a POST learns nothing about tokens).
#pragma once

#include "booth/session_store.h"
#include "booth/share_link.h"

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth {

struct ShareResponse {
    int status = 404;
    std::string contentType;
    std::string body;
    // The body gzip-compressed, made once when the site starts (the viewer script, 1 MB, is a quarter of that
    // compressed); empty when there is none. The server never compresses on the fly: cpp-httplib's own brotli at
    // its highest quality takes ~2 s of CPU for the viewer, which one client could ask for again and again.
    std::shared_ptr<const std::string> gzipBody;
    // Extra headers for this answer (the security headers common to all are ShareSite::commonHeaders()).
    std::vector<std::pair<std::string, std::string>> headers;
};

// Kept sessions by share token, read from each session's session.json. Read again when the sessions folder
// changes (a keep renames a session into it, retention removes one: both change its modification time) or at the
// latest every `maxAge`, so a request never waits for more than one folder's scan. Thread-safe.
class SessionIndex {
public:
    explicit SessionIndex(std::filesystem::path sessionsDirectory,
                          std::chrono::seconds maxAge = std::chrono::seconds(30));

    struct Entry {
        std::filesystem::path folder;
        WallTime keptAt;
    };
    std::optional<Entry> find(const std::string& token);
    // Sessions with a token at the last scan.
    std::size_t size();

private:
    void rescanIfChanged();

    std::filesystem::path directory_;
    std::chrono::seconds maxAge_;
    std::mutex mutex_;
    std::map<std::string, Entry> byToken_;
    std::filesystem::file_time_type scannedMtime_{};
    std::chrono::steady_clock::time_point scannedAt_{};
    bool scanned_ = false;
};

class ShareSite {
public:
    // modelViewerJs: the vendored model-viewer-umd.min.js (empty: the page says the 3-D view is missing, the
    // downloads still work).
    ShareSite(ShareSettings share, SessionStoreSettings sessions, std::filesystem::path modelViewerJs);

    // The answer to `method` on `path` (the request target's path, percent-decoded, without the query) at `now`.
    // Never throws for any input: a session that cannot be read is "not found".
    ShareResponse answer(const std::string& method, const std::string& path, WallTime now);

    // Headers every answer carries: CSP (default-src 'self'), no referrer, nosniff, no framing.
    static const std::vector<std::pair<std::string, std::string>>& commonHeaders();
    // The 404 answer, the same for every kind of miss.
    static ShareResponse notFound();

    // How long a session's page answers: the page lifetime, cut to the session's retention.
    std::chrono::seconds pageLifetime() const;

private:
    ShareResponse page(const std::string& token, const SessionIndex::Entry& session) const;
    ShareResponse file(const SessionIndex::Entry& session, const std::string& name) const;

    ShareSettings share_;
    SessionStoreSettings sessions_;
    SessionIndex index_;
    std::string modelViewer_;  // the script's bytes, read once (empty: none)
    std::shared_ptr<const std::string> modelViewerGzip_, pageCssGzip_;
};

}  // namespace avatarbooth
