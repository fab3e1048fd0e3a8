#include "commands.h"

namespace lat::cli {

Command add_render_command(CLI::App& parent) {
    Command c;
    c.app = parent.add_subcommand("render", "Ray trace a scene to an image");
    c.run = [] { return 0; };
    return c;
}

}  // namespace lat::cli
