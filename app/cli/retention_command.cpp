// `avatarbooth retention [--config FILE]`: applies the sessions' retention rules once and says what it deleted.
//
// The kiosk applies them itself at start and every 10 minutes; this command is for when the booth is not running
// (stopped after an event, while the machine stays on): avatarbooth-retention.timer runs it every hour, so a
// visitor's photos are gone on time whether the booth runs or not. It leaves .pending/ alone (unlike the kiosk at
// start): a running booth's fit in progress lives there.
#include "cli/commands.h"

#include "booth/session_store.h"
#include "config/booth_config.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>

namespace avatarbooth {

void registerRetentionCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("retention", "Delete the photos and sessions older than the configured ages, once");
    auto config = std::make_shared<std::string>();
    cmd->add_option("--config", *config, "Configuration file (default: /etc/avatarbooth/booth.toml when it exists)");
    cmd->callback([config] {
        BoothConfig c;
        if (!config->empty()) c = loadBoothConfig(*config);
        else if (std::filesystem::exists("/etc/avatarbooth/booth.toml")) c = loadBoothConfig("/etc/avatarbooth/booth.toml");
        SessionStore store(c.sessions);
        const RetentionReport r = store.applyRetention(std::chrono::system_clock::now());
        std::cout << "retention in " << c.sessions.directory.string() << ": deleted " << r.photosDeleted
                  << " photo file(s) and " << r.sessionsDeleted << " session(s), " << r.bytesFreed << " bytes freed";
        std::cout << "\n";
    });
}

}  // namespace avatarbooth
