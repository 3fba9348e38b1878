// The output-overwrite rule (core/path_rule.h checkOutputsApart): no output is an input of the
// same run or another output, compared after `..`, symlinks and hard links.
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/path_rule.h"

namespace fs = std::filesystem;

TEST_CASE("an output that is an input or another output is refused, naming both") {
  const fs::path dir = fs::temp_directory_path() / ("rm3d_outputs_" + std::to_string(getpid()));
  fs::create_directories(dir / "sub");
  const std::string world = (dir / "w.lua").string();
  std::ofstream(world) << "world.set{duration = 0.1}\n";
  fs::create_symlink(world, dir / "link.json");
  fs::create_hard_link(world, dir / "hard.json");
  std::string err;
  using rm3d::checkOutputsApart;
  CHECK_FALSE(checkOutputsApart({{"the world script", world}}, {{"--json", world}}, err));
  CHECK(err == "--json " + world + ": is also the world script " + world +
                   " (an output may not overwrite an input of the same run; write it elsewhere)");
  for (const fs::path& p : {dir / "link.json", dir / "hard.json", dir / "sub" / ".." / "w.lua"})
    CHECK_FALSE(checkOutputsApart({{"the world script", world}}, {{"--trace", p.string()}}, err));
  const std::string out = (dir / "o").string();
  CHECK_FALSE(checkOutputsApart({{"the world script", world}}, {{"--json", out}, {"--record", out}}, err));
  CHECK(err ==
        "--record " + out + ": is also the output of --json " + out + " (each output needs its own file)");
  CHECK(checkOutputsApart({{"the world script", world}, {"--fork", ""}},
                          {{"--json", out}, {"--record", (dir / "r.rec").string()}, {"--png", ""}}, err));
  fs::remove_all(dir);
}
