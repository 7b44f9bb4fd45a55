// The visitor's page: routing on a white list, the session index, the page's HTML (see share_site.h).
#include "share/share_site.h"

#include "common/error.h"
#include "common/html_text.h"

#include <nlohmann/json.hpp>
#include <zlib.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <ctime>
#include <fstream>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

constexpr std::uintmax_t kLargestFile = 256u << 20;  // no session file is near this; a bigger one is not sent

// The page's style: one column that fits a phone, the viewer as wide as the screen. No web fonts.
constexpr const char* kPageCss = R"(html { -webkit-text-size-adjust: 100%; }
body { margin: 0; font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; background: #10151c;
       color: #eef2f6; line-height: 1.45; }
main { max-width: 40rem; margin: 0 auto; padding: 1rem; }
h1 { font-size: 1.6rem; margin: 0.3rem 0 0.8rem; }
model-viewer { display: block; width: 100%; height: min(70vh, 34rem); background: #1d2631; border-radius: 12px;
               --poster-color: #1d2631; }
.missing { padding: 2rem 1rem; background: #1d2631; border-radius: 12px; }
.hint, .expires { color: #b8c2cc; font-size: 0.95rem; }
ul.downloads { list-style: none; padding: 0; display: grid; gap: 0.6rem; }
ul.downloads a { display: block; padding: 0.9rem 1rem; border-radius: 10px; background: #2f7de1; color: #fff;
                 text-decoration: none; font-weight: 600; }
ul.downloads small { display: block; font-weight: 400; opacity: 0.85; }
)";

const char* contentTypeOf(const std::string& name) {
    const std::string ext = fs::path(name).extension().string();
    if (ext == ".glb") return "model/gltf-binary";
    if (ext == ".usdz") return "model/vnd.usdz+zip";
    if (ext == ".png") return "image/png";
    if (ext == ".jpg") return "image/jpeg";
    if (ext == ".webp") return "image/webp";
    if (ext == ".pdf") return "application/pdf";
    return "application/octet-stream";
}

// A regular file of the session read whole; nothing for a link, a folder, a missing or an oversized file.
std::optional<std::string> readSessionFile(const fs::path& p) {
    const int fd = ::open(p.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) return std::nullopt;
    struct stat st{};
    std::optional<std::string> out;
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && static_cast<std::uintmax_t>(st.st_size) <= kLargestFile) {
        std::string bytes(static_cast<std::size_t>(st.st_size), '\0');
        std::size_t got = 0;
        while (got < bytes.size()) {
            const ssize_t n = ::read(fd, bytes.data() + got, bytes.size() - got);
            if (n <= 0) break;
            got += static_cast<std::size_t>(n);
        }
        if (got == bytes.size()) out = std::move(bytes);
    }
    ::close(fd);
    return out;
}

std::string html(const std::string& text) { return escapeHtml(text); }

std::string dayOf(WallTime t) {
    const std::time_t tt = std::chrono::system_clock::to_time_t(t);
    std::tm tm{};
    ::localtime_r(&tt, &tm);
    char buffer[64];
    return std::strftime(buffer, sizeof buffer, "%d %B %Y", &tm) ? buffer : "";
}

// The photo of a session named `stem` (front, side) as the folder holds it: front.jpg or front.png.
std::optional<std::string> photoName(const fs::path& folder, const std::string& stem) {
    for (const char* ext : {".jpg", ".png"}) {
        std::error_code ec;
        if (fs::is_regular_file(fs::symlink_status(folder / (stem + ext), ec))) return stem + ext;
    }
    return std::nullopt;
}

// `bytes` as a gzip member (zlib, best compression), for the static files sent to every visitor.
std::shared_ptr<const std::string> gzip(const std::string& bytes) {
    z_stream z{};
    if (deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY) != Z_OK) return nullptr;
    std::string out(deflateBound(&z, static_cast<uLong>(bytes.size())), '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
    z.avail_in = static_cast<uInt>(bytes.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = static_cast<uInt>(out.size());
    const int result = deflate(&z, Z_FINISH);
    out.resize(z.total_out);
    deflateEnd(&z);
    return result == Z_STREAM_END ? std::make_shared<const std::string>(std::move(out)) : nullptr;
}

ShareResponse ok(std::string type, std::string body, std::string cache) {
    ShareResponse r;
    r.status = 200;
    r.contentType = std::move(type);
    r.body = std::move(body);
    r.headers.emplace_back("Cache-Control", std::move(cache));
    return r;
}

}  // namespace

// ---- SessionIndex ----------------------------------------------------------------------------------------------

SessionIndex::SessionIndex(fs::path sessionsDirectory, std::chrono::seconds maxAge)
    : directory_(std::move(sessionsDirectory)), maxAge_(maxAge) {}

void SessionIndex::rescanIfChanged() {
    std::error_code ec;
    const auto mtime = fs::last_write_time(directory_, ec);
    const auto now = std::chrono::steady_clock::now();
    if (scanned_ && !ec && mtime == scannedMtime_ && now - scannedAt_ < maxAge_) return;
    std::map<std::string, Entry> found;
    for (auto it = fs::directory_iterator(directory_, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.empty() || name[0] == '.' || !it->is_directory(ec) || it->is_symlink(ec)) continue;
        std::ifstream in(it->path() / "session.json");
        if (!in) continue;
        try {
            const auto j = nlohmann::json::parse(in);
            const auto token = j.at("share_token").get<std::string>();
            if (!isShareToken(token)) continue;
            found[token] = Entry{it->path(), WallTime(std::chrono::seconds(j.at("kept_at").get<long long>()))};
        } catch (const std::exception&) {
            continue;  // a damaged session.json: that session has no page
        }
    }
    byToken_ = std::move(found);
    scannedMtime_ = mtime;
    scannedAt_ = now;
    scanned_ = true;
}

std::optional<SessionIndex::Entry> SessionIndex::find(const std::string& token) {
    std::lock_guard lock(mutex_);
    rescanIfChanged();
    const auto it = byToken_.find(token);
    if (it == byToken_.end()) return std::nullopt;
    return it->second;
}

std::size_t SessionIndex::size() {
    std::lock_guard lock(mutex_);
    rescanIfChanged();
    return byToken_.size();
}

// ---- ShareSite -------------------------------------------------------------------------------------------------

ShareSite::ShareSite(ShareSettings share, SessionStoreSettings sessions, fs::path modelViewerJs)
    : share_(std::move(share)), sessions_(std::move(sessions)), index_(sessions_.directory) {
    if (!modelViewerJs.empty()) {
        const auto bytes = readSessionFile(modelViewerJs);
        if (!bytes) throw BoothError(ErrorKind::BadConfig, modelViewerJs.string(), "cannot read model-viewer");
        modelViewer_ = *bytes;
        modelViewerGzip_ = gzip(modelViewer_);
    }
    pageCssGzip_ = gzip(kPageCss);
}

std::chrono::seconds ShareSite::pageLifetime() const {
    const auto retention = sessions_.sessionRetention;
    return retention.count() > 0 ? std::min(share_.pageLifetime, retention) : share_.pageLifetime;
}

const std::vector<std::pair<std::string, std::string>>& ShareSite::commonHeaders() {
    // model-viewer (three.js) hands textures to the GPU through blob: URLs, styles its shadow DOM at run time and
    // compiles a WebAssembly decoder it carries ('wasm-unsafe-eval' allows that and not eval()); nothing else is
    // allowed from anywhere but this server.
    static const std::vector<std::pair<std::string, std::string>> headers{
        {"Content-Security-Policy",
         "default-src 'self'; script-src 'self' 'wasm-unsafe-eval'; img-src 'self' blob: data:; "
         "connect-src 'self' blob: data:; style-src 'self' 'unsafe-inline'; worker-src 'self' blob:; "
         "object-src 'none'; base-uri 'none'; "
         "form-action 'none'; frame-ancestors 'none'"},
        {"Referrer-Policy", "no-referrer"},
        {"X-Content-Type-Options", "nosniff"},
        {"X-Frame-Options", "DENY"},
        {"Cross-Origin-Resource-Policy", "same-origin"},
    };
    return headers;
}

ShareResponse ShareSite::notFound() {
    ShareResponse r;
    r.status = 404;
    r.contentType = "text/plain; charset=utf-8";
    r.body = "Not found. Pages of the avatar booth are kept for a limited time.\n";
    r.headers.emplace_back("Cache-Control", "no-store");
    return r;
}

ShareResponse ShareSite::answer(const std::string& method, const std::string& path, WallTime now) {
    if (method != "GET" && method != "HEAD") {
        ShareResponse r;
        r.status = 405;
        r.contentType = "text/plain; charset=utf-8";
        r.body = "Method not allowed.\n";
        r.headers.emplace_back("Allow", "GET, HEAD");
        r.headers.emplace_back("Cache-Control", "no-store");
        return r;
    }
    if (path == "/static/page.css") {
        ShareResponse r = ok("text/css; charset=utf-8", kPageCss, "public, max-age=86400");
        r.gzipBody = pageCssGzip_;
        return r;
    }
    if (path == "/static/model-viewer.js") {
        if (modelViewer_.empty()) return notFound();
        ShareResponse r = ok("text/javascript; charset=utf-8", modelViewer_, "public, max-age=86400");
        r.gzipBody = modelViewerGzip_;
        return r;
    }
    // "/s/" + token, then nothing, "/" or "/" + a file name.
    static const std::string prefix = "/s/";
    if (path.size() < prefix.size() + kShareTokenLength || path.compare(0, prefix.size(), prefix) != 0)
        return notFound();
    const std::string token = path.substr(prefix.size(), kShareTokenLength);
    const std::string rest = path.substr(prefix.size() + kShareTokenLength);
    if (!isShareToken(token)) return notFound();
    // One URL per thing: the page is "/s/TOKEN" exactly (the QR code's), a file "/s/TOKEN/NAME".
    if (!rest.empty() && (rest.size() < 2 || rest[0] != '/')) return notFound();
    const std::string name = rest.empty() ? "" : rest.substr(1);
    static const std::vector<std::string> files{"avatar.glb", "avatar.usdz", "preview.png", "turntable.webp",
                                                "card.pdf",   "front.jpg",   "front.png",   "side.jpg",
                                                "side.png"};
    if (!name.empty() && std::find(files.begin(), files.end(), name) == files.end()) return notFound();
    try {
        const auto session = index_.find(token);
        if (!session || now >= session->keptAt + pageLifetime())
            return notFound();
        return name.empty() ? page(token, *session) : file(*session, name);
    } catch (const std::exception&) {
        return notFound();  // a session that cannot be read (being deleted this moment) is a miss like any other
    }
}

ShareResponse ShareSite::file(const SessionIndex::Entry& session, const std::string& name) const {
    std::string onDisk = name;
    if (name == "preview.png") onDisk = "preview_three_quarter.png";
    const bool photo = name.rfind("front.", 0) == 0 || name.rfind("side.", 0) == 0;
    if (photo && !share_.offerPhotos) return notFound();
    const auto bytes = readSessionFile(session.folder / onDisk);
    if (!bytes) return notFound();
    ShareResponse r = ok(contentTypeOf(name), *bytes, "private, max-age=3600");
    // The AR viewers open the glb and usdz in place; the rest are offered to save.
    if (name != "avatar.glb" && name != "avatar.usdz")
        r.headers.emplace_back("Content-Disposition", "attachment; filename=\"avatar-" + name + "\"");
    return r;
}

ShareResponse ShareSite::page(const std::string& token, const SessionIndex::Entry& session) const {
    const std::string base = "/s/" + token + "/";
    const fs::path& folder = session.folder;
    std::error_code ec;
    const bool hasUsdz = fs::is_regular_file(folder / "avatar.usdz", ec);
    const bool hasPreview = fs::is_regular_file(folder / "preview_three_quarter.png", ec);
    const bool hasTurntable = fs::is_regular_file(folder / "turntable.webp", ec);
    const bool hasCard = fs::is_regular_file(folder / "card.pdf", ec);  // printed at the booth ([print])
    std::string h;
    h += "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
         "<meta name=\"referrer\" content=\"no-referrer\">\n<meta name=\"robots\" content=\"noindex, nofollow\">\n"
         "<title>Your avatar</title>\n<link rel=\"icon\" href=\"data:,\">\n"
         "<link rel=\"stylesheet\" href=\"/static/page.css\">\n";
    if (!modelViewer_.empty()) h += "<script src=\"/static/model-viewer.js\"></script>\n";
    h += "</head>\n<body>\n<main>\n<h1>Your avatar</h1>\n";
    if (!modelViewer_.empty()) {
        h += "<model-viewer src=\"" + html(base) + "avatar.glb\"";
        if (hasUsdz) h += " ios-src=\"" + html(base) + "avatar.usdz\"";
        if (hasPreview) h += " poster=\"" + html(base) + "preview.png\"";
        h += " alt=\"Your 3-D avatar\" camera-controls auto-rotate touch-action=\"pan-y\" shadow-intensity=\"1\""
             " ar ar-modes=\"scene-viewer quick-look\" ar-scale=\"auto\"></model-viewer>\n"
             "<p class=\"hint\">Turn it with a finger. The AR button puts it in the room with you.</p>\n";
    } else {
        h += "<p class=\"missing\">The 3-D view is not installed on this booth; the downloads below work.</p>\n";
    }
    std::vector<std::pair<std::string, std::string>> links;  // href, label
    if (share_.offerDownloads) {
        links.emplace_back(base + "avatar.glb", "3-D model<small>avatar.glb (glTF: Android, Windows, Blender)</small>");
        if (hasUsdz) links.emplace_back(base + "avatar.usdz", "3-D model for iPhone and iPad<small>avatar.usdz</small>");
        if (hasPreview) links.emplace_back(base + "preview.png", "Picture<small>avatar-preview.png</small>");
        if (hasTurntable)
            links.emplace_back(base + "turntable.webp", "Turning picture<small>avatar-turntable.webp (animated)</small>");
        if (hasCard) links.emplace_back(base + "card.pdf", "The printed card<small>avatar-card.pdf</small>");
    }
    if (share_.offerPhotos)
        for (const char* stem : {"front", "side"})
            if (const auto photo = photoName(folder, stem))
                links.emplace_back(base + *photo, std::string(stem == std::string("front") ? "Front photo" : "Side photo") +
                                                      "<small>" + html("avatar-" + *photo) + "</small>");
    if (!links.empty()) {
        h += "<ul class=\"downloads\">\n";
        for (const auto& [href, label] : links) {
            const bool inPlace = href.ends_with(".glb") || href.ends_with(".usdz");
            h += "<li><a href=\"" + html(href) + "\"" + (inPlace ? " download" : "") + ">" + label + "</a></li>\n";
        }
        h += "</ul>\n";
    }
    h += "<p class=\"expires\">This page is deleted after " + html(dayOf(session.keptAt + pageLifetime())) +
         ". Save what you want to keep.</p>\n</main>\n</body>\n</html>\n";
    return ok("text/html; charset=utf-8", std::move(h), "no-store");
}

}  // namespace avatarbooth
