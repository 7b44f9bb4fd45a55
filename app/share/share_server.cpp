// The visitor's pages over cpp-httplib (see share_server.h). httplib parses requests; ShareSite answers them.
#include "share/share_server.h"

#include "common/error.h"

#include <httplib.h>

#include <sys/socket.h>

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

namespace avatarbooth {
namespace {

// httplib's ThreadPool queues connections without limit: a crowd (or an attacker) would grow it, and the memory
// of the booth, without end. This pool holds at most `queue` waiting connections; when they are all taken, the
// accepting thread waits here, so further connections wait in the kernel's listen backlog (and beyond it are
// refused by the kernel), never in the booth's memory.
class BoundedPool : public httplib::TaskQueue {
    // cpp-httplib 0.11 (bookworm) has `void enqueue`; later ones (trixie's 0.18) return whether the task was taken,
    // a false making the server close the connection. This pool takes every task (it waits for room instead).
    using EnqueueResult = decltype(std::declval<httplib::TaskQueue&>().enqueue(std::function<void()>{}));
    template <typename Result = EnqueueResult>
    static Result taken() {
        if constexpr (std::is_void_v<Result>) return;
        else return true;
    }

public:
    BoundedPool(std::size_t workers, std::size_t queue) : limit_(queue) {
        for (std::size_t i = 0; i < workers; ++i) threads_.emplace_back([this] { work(); });
    }

    EnqueueResult enqueue(std::function<void()> fn) override {
        std::unique_lock lock(mutex_);
        spaceFree_.wait(lock, [&] { return jobs_.size() < limit_ || shutdown_; });
        if (shutdown_) {
            lock.unlock();
            fn();  // the server is stopping: the connection is answered (and closed) by this thread
            return taken();
        }
        jobs_.push_back(std::move(fn));
        jobReady_.notify_one();
        return taken();
    }

    void shutdown() override {
        {
            std::lock_guard lock(mutex_);
            shutdown_ = true;
        }
        jobReady_.notify_all();
        spaceFree_.notify_all();
        for (auto& t : threads_) t.join();
    }

private:
    void work() {
        for (;;) {
            std::function<void()> fn;
            {
                std::unique_lock lock(mutex_);
                jobReady_.wait(lock, [&] { return !jobs_.empty() || shutdown_; });
                if (jobs_.empty()) return;  // shut down and nothing left
                fn = std::move(jobs_.front());
                jobs_.pop_front();
                spaceFree_.notify_one();
            }
            fn();
        }
    }

    std::size_t limit_;
    std::mutex mutex_;
    std::condition_variable jobReady_, spaceFree_;
    std::deque<std::function<void()>> jobs_;
    std::vector<std::thread> threads_;
    bool shutdown_ = false;
};

// Everything a request may carry: the page needs no body, a browser's headers are 1-2 KiB.
constexpr std::size_t kMaxBody = 1024;
constexpr std::size_t kMaxHeaders = 64;
constexpr std::size_t kMaxHeaderBytes = 16 * 1024;
// Connections the kernel completes and holds for us while every worker is busy. httplib listens with a backlog of
// 5: a crowd's phones arriving at once (a group photo, a school class) would mostly have their handshakes dropped
// and retried after 1, 3, 7, 15 s; 64 waiting connections cost the kernel a few KiB.
constexpr int kListenBacklog = 64;

// Whether an Accept-Encoding header lists gzip (without q=0).
bool acceptsGzip(const std::string& header) {
    std::size_t at = 0;
    while ((at = header.find("gzip", at)) != std::string::npos) {
        const std::size_t end = header.find(',', at);
        const std::string item = header.substr(at, end == std::string::npos ? std::string::npos : end - at);
        if (item.find("q=0") == std::string::npos || item.find("q=0.") != std::string::npos) return true;
        at += 4;
    }
    return false;
}

}  // namespace

struct ShareServer::Impl {
    std::unique_ptr<httplib::Server> server;
    int listeningSocket = -1;  // the last socket httplib made to listen on (set_socket_options sees each)
    std::atomic<std::uint64_t> served{0}, notFound{0}, refused{0}, serverErrors{0};
};

ShareServer::ShareServer(ShareSite& site, const ShareSettings& settings) : impl_(std::make_unique<Impl>()) {
    if (!settings.tlsCertificate.empty()) {
#ifdef CPPHTTPLIB_OPENSSL_SUPPORT
        auto tls = std::make_unique<httplib::SSLServer>(settings.tlsCertificate.c_str(), settings.tlsKey.c_str());
        if (!tls->is_valid())
            throw BoothError(ErrorKind::BadConfig, settings.tlsCertificate.string(),
                             "cannot load the certificate and its key (" + settings.tlsKey.string() +
                                 "): both PEM, matching, readable by the service's user");
        impl_->server = std::move(tls);
        tls_ = true;
#else
        throw BoothError(ErrorKind::BadConfig, settings.tlsCertificate.string(),
                         "this build's cpp-httplib has no TLS support: leave tls_certificate empty");
#endif
    } else {
        impl_->server = std::make_unique<httplib::Server>();
    }
    httplib::Server& s = *impl_->server;
    const auto workers = static_cast<std::size_t>(std::max(1, settings.workers));
    s.new_task_queue = [workers] { return new BoundedPool(workers, workers); };
    s.set_read_timeout(settings.readTimeout);
    s.set_write_timeout(std::chrono::seconds(10));  // a phone on a weak link still gets a 3 MB file in that time
    s.set_keep_alive_timeout(settings.readTimeout.count());
    s.set_keep_alive_max_count(20);
    s.set_payload_max_length(kMaxBody);
    // httplib's default options plus remembering the socket, whose backlog bind() raises. Not SO_REUSEPORT (a
    // default in some httplib versions): another process of the same user could then listen on the same port.
    s.set_socket_options([impl = impl_.get()](socket_t sock) {
        const int yes = 1;
        ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
        impl->listeningSocket = sock;
    });
    {
        httplib::Headers common;
        for (const auto& [key, value] : ShareSite::commonHeaders()) common.emplace(key, value);
        s.set_default_headers(common);
    }
    Impl* impl = impl_.get();
    // Every request is answered here, before httplib's router and before a body is read: ShareSite is the whole
    // site, and a request with a body is refused without reading it.
    s.set_pre_routing_handler([&site, impl](const httplib::Request& req, httplib::Response& res) {
        std::size_t headerBytes = 0;
        for (const auto& [key, value] : req.headers) headerBytes += key.size() + value.size() + 4;
        ShareResponse answer;
        if (req.headers.size() > kMaxHeaders || headerBytes > kMaxHeaderBytes) {
            answer.status = 431;
            answer.contentType = "text/plain; charset=utf-8";
            answer.body = "Request header fields too large.\n";
        } else if (req.has_header("Content-Length") && req.get_header_value("Content-Length") != "0" &&
                   (req.method == "GET" || req.method == "HEAD")) {
            answer.status = 413;
            answer.contentType = "text/plain; charset=utf-8";
            answer.body = "A request to this server carries no body.\n";
        } else {
            answer = site.answer(req.method, req.path, std::chrono::system_clock::now());
        }
        res.status = answer.status;
        for (const auto& [key, value] : answer.headers) res.set_header(key, value);
        if (answer.status >= 400) res.set_header("Connection", "close");  // nothing more from a client that missed
        // The body through a sized content provider: httplib then sends it as it is (it compresses only bodies set
        // with set_content, with brotli at quality 11: seconds of CPU per MB on a Pi). Static files go gzipped,
        // compressed once at start, to clients that accept it.
        std::shared_ptr<const std::string> body;
        if (answer.gzipBody && acceptsGzip(req.get_header_value("Accept-Encoding"))) {
            body = answer.gzipBody;
            res.set_header("Content-Encoding", "gzip");
        } else {
            body = std::make_shared<const std::string>(std::move(answer.body));
        }
        if (answer.gzipBody) res.set_header("Vary", "Accept-Encoding");
        res.set_content_provider(body->size(), answer.contentType,
                                 [body](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
                                     return sink.write(body->data() + offset, length);
                                 });
        return httplib::Server::HandlerResponse::Handled;
    });
    // Counted after every answer, including those httplib makes itself (400 for a malformed request, 413, 414).
    s.set_logger([impl](const httplib::Request&, const httplib::Response& res) {
        if (res.status >= 500) ++impl->serverErrors;
        else if (res.status == 404) ++impl->notFound;
        else if (res.status >= 400) ++impl->refused;
        else ++impl->served;
    });
    // No error handler: httplib's own refusals (a request it could not parse, a line too long) go out with an empty
    // body, and one would run for the site's answers too (every 404), replacing their bodies.
    s.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
        res.status = 500;
        res.set_content("Internal error.\n", "text/plain; charset=utf-8");
    });
}

ShareServer::~ShareServer() { stop(); }

int ShareServer::bind(const std::string& host, int port) {
    httplib::Server& s = *impl_->server;
    const std::string where = (host.find(':') != std::string::npos ? "[" + host + "]" : host) + ":" + std::to_string(port);
    int bound = port;
    if (port == 0) {
        bound = s.bind_to_any_port(host);
        if (bound <= 0) throw BoothError(ErrorKind::Device, where, "cannot listen there");
    } else if (!s.bind_to_port(host, port)) {
        throw BoothError(ErrorKind::Device, where,
                         "cannot listen there (in use, not an address of this machine, or a port below 1024 "
                         "without CAP_NET_BIND_SERVICE)");
    }
    // listen() again on a listening socket sets its backlog (Linux).
    if (impl_->listeningSocket >= 0) ::listen(impl_->listeningSocket, kListenBacklog);
    return bound;
}

void ShareServer::run() { impl_->server->listen_after_bind(); }

void ShareServer::stop() {
    if (impl_ && impl_->server) impl_->server->stop();
}

ShareCounters ShareServer::counters() const {
    return {impl_->served.load(), impl_->notFound.load(), impl_->refused.load(), impl_->serverErrors.load()};
}

}  // namespace avatarbooth
