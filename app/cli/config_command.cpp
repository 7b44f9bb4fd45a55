// `avatarbooth config --print-default | --reference | --check FILE`: the configuration's schema as a file, as the
// README's Markdown reference, and checking a file against it.
#include "cli/commands.h"

#include "config/booth_config.h"
#include "config/config_schema.h"

#include <iostream>
#include <memory>
#include <string>

namespace avatarbooth {

void registerConfigCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("config", "Print the documented default configuration or its reference, or check a file");
    struct Options {
        bool printDefault = false;
        bool reference = false;
        std::string check;
    };
    auto o = std::make_shared<Options>();
    cmd->add_flag("--print-default", o->printDefault,
                  "Print the default booth.toml, every key with its doc (what the package installs)");
    cmd->add_flag("--reference", o->reference, "Print every key as Markdown tables (the README's config reference)");
    cmd->add_option("--check", o->check, "Check a configuration file: every mistake, each naming file, line and key (exit code 6)")
        ->check(CLI::ExistingFile);
    cmd->require_option(1);
    cmd->callback([o] {
        if (o->printDefault) std::cout << renderDefaultConfig();
        else if (o->reference) std::cout << renderConfigReference();
        else {
            // A bad file throws ConfigErrors: main prints each mistake as "FILE:LINE: key: ..." and exits with 6.
            loadBoothConfig(o->check);
            std::cout << o->check << ": OK\n";
        }
    });
}

}  // namespace avatarbooth
