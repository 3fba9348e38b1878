// RM3D's version, for `rm3d --version` and the "version" field of run summaries.
#pragma once

namespace rm3d {

/// The version of this build ("dev" until releases are numbered).
const char* rm3dVersion();

}  // namespace rm3d
