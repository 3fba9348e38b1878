// RM3D's version (app/version.h).
#include "app/version.h"

namespace rm3d {

const char* rm3dVersion() {
  return "dev";
}

}  // namespace rm3d
