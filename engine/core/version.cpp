// rm3dVersion(): the strings come from the build (CMakeLists.txt, cmake/version_info.cmake).
#include "core/version.h"

#include "rm3d_version_info.h"

std::string rm3dVersion() {
  const std::string rev = RM3D_GIT_REVISION;
  return rev.empty() ? std::string(RM3D_PROJECT_VERSION) : std::string(RM3D_PROJECT_VERSION) + "+" + rev;
}
