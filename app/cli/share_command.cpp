// `avatarbooth share [--config FILE] [--listen ADDRESS:PORT]`: serves the visitors' pages (issue 23, "take it
// home") until stopped: app/share/. Its own process and unit (systemd/avatarbooth-share.service), so that the kiosk
// keeps PrivateNetwork=yes and this process may only read the sessions folder.
//
// With [share] enabled = false (the default) it listens nowhere: it says so and exits with the bad-config code, so
// a unit started by mistake fails visibly instead of serving pages the operator did not turn on.
#include "cli/commands.h"
#include "cli/exit_codes.h"

#include "batch/batch_report.h"
#include "booth/share_link.h"
#include "config/booth_config.h"
#include "share/share_server.h"

#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

#include <pthread.h>
#include <signal.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <thread>

namespace avatarbooth {

void registerShareCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("share", "Serve the visitors' own pages (QR code on the thanks screen), until stopped");
    struct Options {
        std::string config;
        std::string listen;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--config", o->config, "Configuration file (default: /etc/avatarbooth/booth.toml when it exists)");
    cmd->add_option("--listen", o->listen, "ADDRESS:PORT instead of [share] listen (port 0: any free port)");
    cmd->callback([o] {
        BoothConfig c;
        std::string file = o->config;
        if (file.empty() && std::filesystem::exists("/etc/avatarbooth/booth.toml")) file = "/etc/avatarbooth/booth.toml";
        if (!file.empty()) c = loadBoothConfig(file);
        const std::string source = file.empty() ? std::string("the built-in defaults") : file;
        if (!c.share.enabled) {
            std::cerr << "avatarbooth share: sharing is off ([share] enabled = false in " << source
                      << "): nothing listens. Set enabled = true there to serve the visitors' pages.\n";
            throw CLI::RuntimeError(kExitBadConfig);
        }
        const std::string listen = o->listen.empty() ? c.share.listen : o->listen;
        const auto address = parseListenAddress(listen, /*anyPort=*/true);
        if (!address) throw BoothError(ErrorKind::BadConfig, "--listen", "\"" + listen + "\" is not ADDRESS:PORT");

        // SIGINT and SIGTERM are taken by a thread of their own (blocked here before any thread starts, so every
        // thread inherits the mask): it stops the server, whose run() then returns.
        sigset_t stopSignals;
        sigemptyset(&stopSignals);
        sigaddset(&stopSignals, SIGINT);
        sigaddset(&stopSignals, SIGTERM);
        pthread_sigmask(SIG_BLOCK, &stopSignals, nullptr);

        const std::filesystem::path viewer = findModelViewer();
        if (viewer.empty()) spdlog::warn("model-viewer not found: pages offer the downloads without the 3-D view");
        ShareSite site(c.share, c.sessions, viewer);
        ShareServer server(site, c.share);
        const int port = server.bind(address->host, address->port);
        const std::string where = (address->host.find(':') != std::string::npos ? "[" + address->host + "]" : address->host) +
                                  ":" + std::to_string(port);
        // One line on stdout (the journal; tests read the port from it).
        std::cout << "avatarbooth share: listening on " << where << (server.tls() ? " (https)" : " (http)")
                  << ", pages at " << shareBaseUrl(c.share) << "/s/<token>, sessions in "
                  << c.sessions.directory.string() << std::endl;
        std::thread signals([&server, stopSignals] {
            int signal = 0;
            sigwait(&stopSignals, &signal);
            server.stop();
        });
        sd_notify(0, "READY=1");
        server.run();
        // run() also returns when the listening socket fails; wake the signal thread in either case.
        pthread_kill(signals.native_handle(), SIGTERM);
        signals.join();
        const ShareCounters n = server.counters();
        std::cout << "avatarbooth share: stopped; " << n.served << " served, " << n.notFound << " not found, "
                  << n.refused << " refused, " << n.serverErrors << " server errors" << std::endl;
    });
}

}  // namespace avatarbooth
