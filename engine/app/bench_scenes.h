// The names of `rm3d bench`'s scenes, for its --help (generated from the scene table, so the help
// lists every scene there is).
#pragma once

#include <string>

namespace rm3d {

/// One line per scene: "  snake_150        N SuperBots docked in one chain, ... (150 modules)".
std::string benchSceneHelp();

}  // namespace rm3d
