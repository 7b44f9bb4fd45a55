// `avatarbooth make-base-head -o DIR`
#include "cli/commands.h"

namespace avatarbooth {
void registerMakeBaseHeadCommand(CLI::App& app) {
    app.add_subcommand("make-base-head", "Write the built-in base head (glb) and its feature file");
}
}  // namespace avatarbooth
