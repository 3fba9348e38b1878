// The version of this rm3d: the project version and the git revision it was built from.
#pragma once

#include <string>

/// "0.1.0+c36c2b0" (project version + `git describe --always --dirty` at build time, "-dirty"
/// when the tree had uncommitted changes), or "0.1.0" when built outside a git tree.
std::string rm3dVersion();

namespace rm3d {
using ::rm3dVersion;
}
