// `avatarbooth share`: the visitor's pages (share_site.h) over HTTP or HTTPS with cpp-httplib (Debian
// libcpp-httplib-dev), with limits on what one client can take: a bounded pool of workers and queue of connections,
// a read timeout, request line, header and body size limits (httplib's own, compiled into Debian's library: 8 KiB
// for the request line and for a header line), and GET/HEAD only.
#pragma once

#include "share/share_site.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

namespace avatarbooth {

// What the server answered since it started (for the log, `avatarbooth check` and the tests).
struct ShareCounters {
    std::uint64_t served = 0;        // 2xx
    std::uint64_t notFound = 0;      // 404: unknown, malformed or expired tokens and any other path
    std::uint64_t refused = 0;       // 4xx other than 404: wrong method, too large, malformed requests
    std::uint64_t serverErrors = 0;  // 5xx
};

class ShareServer {
public:
    // TLS when settings.tlsCertificate is set; throws BoothError(BadConfig) naming the certificate or key when they
    // cannot be loaded.
    ShareServer(ShareSite& site, const ShareSettings& settings);
    ~ShareServer();
    ShareServer(const ShareServer&) = delete;
    ShareServer& operator=(const ShareServer&) = delete;

    // Binds host:port (port 0: any free port, for tests) and returns the port. Throws BoothError(Device) naming the
    // address when it cannot (in use, not an address of this machine, a privileged port without the capability).
    int bind(const std::string& host, int port);
    // Serves until stop() (from another thread or a signal handler's thread); returns once no worker runs.
    void run();
    void stop();
    bool tls() const { return tls_; }

    ShareCounters counters() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    bool tls_ = false;
};

}  // namespace avatarbooth
