// `avatarbooth fit --front F --side S [--background B] -o OUT/`
#include "cli/commands.h"

namespace avatarbooth {
void registerFitCommand(CLI::App& app) {
    app.add_subcommand("fit", "Fit a 3-D head to a front and a side photo");
}
}  // namespace avatarbooth
