// The path rule (core/path_rule.h): what a script may name, after `..` and symlinks.
#include "core/path_rule.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using rm3d::findScriptFile;
using rm3d::ScriptFile;

namespace {

struct Tree {
  fs::path root = fs::temp_directory_path() / ("rm3d_path_rule_" + std::to_string(getpid()));
  Tree() {
    fs::remove_all(root);
    fs::create_directories(root / "proj" / "worlds");
    fs::create_directories(root / "outside");
    std::ofstream(root / "proj" / "worlds" / "b.lua") << "return 1\n";
    std::ofstream(root / "proj" / "lib.lua") << "return 2\n";
    std::ofstream(root / "outside" / "evil.lua") << "return 'secret'\n";
    fs::create_symlink(root / "outside" / "evil.lua", root / "proj" / "worlds" / "link.lua");
    fs::create_symlink(root / "proj" / "lib.lua", root / "proj" / "worlds" / "inner_link.lua");
  }
  ~Tree() { fs::remove_all(root); }
  std::vector<std::string> folders() const {
    return {(root / "proj" / "worlds").string(), (root / "proj").string()};
  }
  ScriptFile find(const std::string& name) const {
    return findScriptFile(name, folders(), folders(), nullptr);
  }
};

}  // namespace

TEST_CASE("relative names resolve in the script's folder first, then the project root") {
  Tree t;
  CHECK(t.find("b.lua").status == ScriptFile::Status::Found);
  CHECK(t.find("b.lua").path == (t.root / "proj" / "worlds" / "b.lua").string());
  CHECK(t.find("lib.lua").path == (t.root / "proj" / "lib.lua").string());
  CHECK(t.find("../lib.lua").status == ScriptFile::Status::Found);  // worlds/.. is the project root
  CHECK(t.find("nope.lua").status == ScriptFile::Status::Missing);
  CHECK(t.find("inner_link.lua").status == ScriptFile::Status::Found);  // a symlink that stays inside
}

TEST_CASE("absolute paths, .. and symlinks that leave the folders are refused, existing or not") {
  Tree t;
  const std::string evil = (t.root / "outside" / "evil.lua").string();
  CHECK(t.find(evil).status == ScriptFile::Status::Outside);
  CHECK(t.find("../../outside/evil.lua").status == ScriptFile::Status::Outside);
  CHECK(t.find("../../outside/missing.lua").status == ScriptFile::Status::Outside);
  CHECK(t.find("/etc/hostname").status == ScriptFile::Status::Outside);
  CHECK(t.find("link.lua").status == ScriptFile::Status::Outside);
  CHECK(t.find((t.root / "proj" / "lib.lua").string()).status == ScriptFile::Status::Found);  // inside
  const std::string msg = rm3d::outsideMessage("/etc/hostname", t.folders());
  CHECK(msg.find("'/etc/hostname' lies outside the folders scripts may read files from") == 0);
  CHECK(msg.find("docs/limits.md") != std::string::npos);
}

TEST_CASE("pathInside compares whole components") {
  CHECK(rm3d::pathInside("/a/b/c", "/a/b"));
  CHECK(rm3d::pathInside("/a/b", "/a/b/"));
  CHECK_FALSE(rm3d::pathInside("/a/bc", "/a/b"));
  CHECK_FALSE(rm3d::pathInside("/a", "/a/b"));
}
