// Finding the data root (data_root.h). RM3D_SOURCE_DIR, RM3D_BINARY_DIR and RM3D_DATA_FROM_BIN
// come from the build (engine/CMakeLists.txt).
#include "app/data_root.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace fs = std::filesystem;

namespace rm3d {

namespace {

std::string normal(const fs::path& p) {
  std::error_code ec;
  const fs::path a = fs::absolute(p, ec);
  return (ec ? p : a).lexically_normal().string();
}

/// The running executable's folder (from /proc/self/exe), or empty.
fs::path executableDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

}  // namespace

bool isDataRoot(const std::string& dir) {
  std::error_code ec;
  return !dir.empty() && fs::is_directory(fs::path(dir) / "assets" / "modules", ec);
}

DataRoot findDataRoot(const std::string& given) {
  DataRoot r;
  auto found = [&](const std::string& path, const char* from) {
    r.path = normal(path);
    r.from = from;
    return r;
  };
  if (!given.empty()) {
    if (isDataRoot(given)) return found(given, "--root");
    r.error = "--root " + given + ": not an RM3D project (expected " +
              normal(fs::path(given) / "assets/modules") + "/ with the module types)";
    return r;
  }
  const fs::path exeDir = executableDir();
  if (!exeDir.empty()) {
    const std::string installed = normal(exeDir / RM3D_DATA_FROM_BIN);
    if (isDataRoot(installed)) return found(installed, "installed");
    r.looked.push_back(installed + " (next to the executable, where `cmake --install` puts the data)");
  }
  if (const char* env = std::getenv("RM3D_ROOT"); env && *env) {
    if (isDataRoot(env)) return found(env, "RM3D_ROOT");
    r.error = "RM3D_ROOT=" + std::string(env) + ": not an RM3D project (expected " +
              normal(fs::path(env) / "assets/modules") + "/ with the module types)";
    return r;
  }
  r.looked.push_back("$RM3D_ROOT (not set)");
  std::error_code ec;
  const fs::path cwd = fs::current_path(ec);
  if (!ec) {
    for (fs::path d = cwd;; d = d.parent_path()) {
      if (isDataRoot(d.string())) return found(d.string(), "the current project");
      if (d == d.root_path() || d.parent_path() == d) break;
    }
    r.looked.push_back(cwd.string() + " and its parents (the current project)");
  }
  // A binary in the folder it was built in uses that checkout; a copy elsewhere does not.
  std::error_code e1;
  if (!exeDir.empty() && fs::equivalent(exeDir, RM3D_BINARY_DIR, e1) && isDataRoot(RM3D_SOURCE_DIR))
    return found(RM3D_SOURCE_DIR, "the build's source tree");
  r.looked.push_back(std::string(RM3D_SOURCE_DIR) + " (the source tree, only for the binary in " +
                     RM3D_BINARY_DIR + ")");
  r.error = "no RM3D data found (module types in assets/modules/, lua/, behaviors/); looked in:";
  for (const std::string& l : r.looked) r.error += "\n  " + l;
  r.error += "\ngive the project with --root DIR or RM3D_ROOT=DIR";
  return r;
}

}  // namespace rm3d
