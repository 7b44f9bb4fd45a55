// The avatarbooth executable: one binary, one subcommand per job (run, fit, batch, check, config, ...: cli/*.cpp).
#include "cli/commands.h"
#include "cli/exit_codes.h"
#include "common/heap_reuse.h"

#include <spdlog/spdlog.h>

#include <iostream>
#include <sstream>
#include <string>

int main(int argc, char** argv) {
    avatarbooth::keepFreedBuffersForReuse();
    CLI::App app{"avatarbooth: a photo booth that turns a front and a side photo into a 3-D head"};
    app.set_version_flag("--version", std::string("avatarbooth ") + AVATARBOOTH_VERSION);
    app.require_subcommand(1);
    bool verbose = false;
    app.add_flag("-v,--verbose", verbose, "Log each stage as it runs");
    app.footer("Exit codes: 0 ok, 1 internal error, 2 usage, 3 bad input file, 4 no face found,\n"
               "            5 photos do not match, 6 bad config, 7 output not writable,\n"
               "            8 device missing or busy (camera, buttons, display), 9 some batch sessions failed,\n"
               "            130 interrupted (Ctrl-C).");
    avatarbooth::registerRunCommand(app);
    avatarbooth::registerFitCommand(app);
    avatarbooth::registerBatchCommand(app);
    avatarbooth::registerMakeBaseHeadCommand(app);
    avatarbooth::registerToonCommand(app);
    avatarbooth::registerMakeVisitorCommand(app);
    avatarbooth::registerBenchCommand(app);
    avatarbooth::registerCheckCommand(app);
    avatarbooth::registerRetentionCommand(app);
    avatarbooth::registerConfigCommand(app);
    avatarbooth::registerShareCommand(app);
    app.parse_complete_callback([&] { spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::warn); });
    try {
        app.parse(argc, argv);
    } catch (const CLI::RuntimeError& e) {
        // A command that has reported its own failure (e.g. `check`) and exits with the code it chose.
        return e.get_exit_code();
    } catch (const CLI::ParseError& e) {
        // --help and --version are "errors" with code 0; every real usage error exits with 2.
        const int code = app.exit(e);
        return code == 0 ? avatarbooth::kExitOk : avatarbooth::kExitUsage;
    } catch (const avatarbooth::BoothError& e) {
        // One error a line (a configuration file with several mistakes lists them all).
        std::istringstream lines(e.what());
        for (std::string line; std::getline(lines, line);) std::cerr << "avatarbooth: error: " << line << "\n";
        return avatarbooth::exitCodeFor(e.kind());
    } catch (const std::exception& e) {
        std::cerr << "avatarbooth: internal error: " << e.what() << "\n";
        return avatarbooth::kExitInternal;
    }
    return avatarbooth::kExitOk;
}
