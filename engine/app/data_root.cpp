// Finding the data root (data_root.h). RM3D_SOURCE_DIR, RM3D_BINARY_DIR and RM3D_DATA_FROM_BIN
// come from the build (engine/CMakeLists.txt).
#include "app/data_root.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <vector>

#include "script/lua_vm.h"

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

std::string worldSummary(const std::string& source, size_t limit) {
  std::string text;
  size_t at = 0;
  for (int n = 0; n < 12 && at < source.size(); ++n) {
    const size_t end = std::min(source.find('\n', at), source.size());
    const std::string line = source.substr(at, end - at);
    at = end + 1;
    if (line.rfind("--", 0) != 0) break;
    const size_t from = line.find_first_not_of("- ");
    if (from == std::string::npos) break;  // an empty comment line ends the paragraph
    text += (text.empty() ? "" : " ") + line.substr(from);
    if (text.size() > 400) break;
  }
  // The file is anyone's: invalid bytes become U+FFFD and control characters (a terminal's escape
  // sequences, a carriage return) a space, so what is shown is text and only text.
  makeValidUtf8(text);
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = ' ';
  if (const size_t colon = text.find(": "); colon != std::string::npos && colon > 4 &&
                                            text.compare(colon - 4, 4, ".lua") == 0 &&
                                            text.find(' ') >= colon)
    text.erase(0, colon + 2);
  if (!text.empty() && text[0] >= 'a' && text[0] <= 'z') text[0] = char(text[0] - 'a' + 'A');
  // The first sentence: up to ". " (not inside "Fig. 5" or "e.g. x": the next word starts upper-case).
  for (size_t p = text.find(". "); p != std::string::npos; p = text.find(". ", p + 1))
    if (p + 2 < text.size() && std::isupper(static_cast<unsigned char>(text[p + 2])) &&
        !(p >= 3 && text.compare(p - 3, 3, "Fig") == 0)) {
      text.resize(p + 1);
      break;
    }
  if (text.size() > limit) {  // cut at a word, never inside a character
    size_t cut = text.rfind(' ', limit);
    if (cut == std::string::npos || cut < limit / 2) {
      cut = limit;
      while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
    }
    text = text.substr(0, cut) + "...";
  }
  text.erase(text.find_last_not_of(' ') + 1);
  return text;
}

// --- World paths, `rm3d worlds`, `rm3d init` ------------------------------------------------------

namespace {

/// The opening comment of a world file (its first lines, read whole).
std::string firstComment(const fs::path& file) {
  std::ifstream in(file);
  std::string line, text;
  for (int n = 0; n < 12 && std::getline(in, line); ++n) text += line + "\n";
  return worldSummary(text, 90);
}

}  // namespace

int listWorldsCommand(const std::string& root) {
  const fs::path dir = fs::path(root) / "worlds";
  std::error_code ec;
  std::vector<fs::path> worlds;
  // worlds/*.lua and one folder down (worlds/python/*.lua, the Python examples' worlds).
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code e2;
    if (it->path().extension() == ".lua" && it->is_regular_file(e2)) worlds.push_back(it->path());
    if (!it->is_directory(e2) || it->is_symlink(e2)) continue;
    for (fs::directory_iterator in(it->path(), e2), stop; !e2 && in != stop; in.increment(e2))
      if (in->path().extension() == ".lua" && in->is_regular_file(e2)) worlds.push_back(in->path());
  }
  if (ec || worlds.empty()) {
    std::fprintf(stderr, "rm3d worlds: no worlds in %s (the data root is %s)\n", dir.string().c_str(),
                 root.c_str());
    return 2;
  }
  std::sort(worlds.begin(), worlds.end());
  std::printf("%zu world%s in %s/ (run one from any folder: rm3d run worlds/NAME.lua):\n", worlds.size(),
              worlds.size() == 1 ? "" : "s", dir.string().c_str());
  for (const fs::path& w : worlds) {
    const std::string name = "worlds/" + w.lexically_relative(dir).generic_string();
    std::printf("  %-32s %s\n", name.c_str(), firstComment(w).c_str());
  }
  return 0;
}

namespace {

const char* const kHelloWorld =
    R"(-- hello.lua: one SuperBot nodding on the ground; a first world to change (docs/getting-started.md).
world.set{dt = 1 / 60, duration = 3, seed = 1}
world.ground{friction = 0.8}
local bot = world.spawn("superbot", {name = "bot", behavior = "../behaviors/hello.lua"})
world.place_on_ground(bot)
world.on_end(function(t)
  expect(bot:error() == nil, "the module did not fault")
  print(string.format("bot at x=%.3f m after %.1f s", bot:position().x, t))
end)
)";

const char* const kHelloBehaviour =
    R"(-- hello.lua: nods the front bracket once a second (module.joint, params, sim, log).
local pitch = module.joint("pitch")
local steps = 0

function step(dt)
  pitch:set_target(0.5 * math.sin(2 * math.pi * sim.time()))
  if steps % math.floor(1 / dt + 0.5) == 0 then log(string.format("pitch %.3f rad", pitch:angle())) end
  steps = steps + 1
end
)";

/// JSON text of a string (paths may hold quotes or backslashes).
std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace

int initProjectCommand(const std::string& dir, const std::string& root) {
  if (dir.empty()) {
    std::fprintf(
        stderr,
        "rm3d init: the folder name is empty (expected a folder to make, e.g. rm3d init myproject)\n");
    return 2;
  }
  const fs::path base(dir);
  const std::string meta = (fs::path(root) / "lua" / "meta").lexically_normal().string();
  const std::string lib = (fs::path(root) / "lua").lexically_normal().string();
  const std::string luarc =
      "{\n  \"runtime.version\": \"Lua 5.4\",\n"
      "  \"runtime.path\": [\"?.lua\", \"lua/?.lua\", \"behaviors/?.lua\"],\n"
      "  \"workspace.library\": [" +
      jsonString(meta) + ", " + jsonString(lib) +
      "],\n"
      "  \"workspace.checkThirdParty\": false,\n"
      "  \"diagnostics.globals\": [\"world\", \"expect\", \"args\", \"log\", \"module\", \"sim\", "
      "\"params\", "
      "\"state\", \"noise\",\n                          \"percepts\", \"actions\", \"init\", \"step\", "
      "\"on_reload\", \"on_dock\"]\n}\n";
  const std::vector<std::pair<fs::path, std::string>> files = {
      {base / "worlds" / "hello.lua", kHelloWorld},
      {base / "behaviors" / "hello.lua", kHelloBehaviour},
      {base / ".luarc.json", luarc},
  };
  std::error_code ec;
  // symlink_status: a link, even one to nothing, is never written through (it would put a file
  // outside the folder); nor is a sub-folder that is a link.
  for (const auto& [path, text] : files) {
    if (fs::exists(fs::symlink_status(path, ec))) {
      std::fprintf(stderr, "rm3d init: %s already exists (init never overwrites; choose a new folder)\n",
                   path.string().c_str());
      return 2;
    }
  }
  for (const fs::path& d : {base / "worlds", base / "behaviors", base / "lua"}) {
    if (fs::is_symlink(fs::symlink_status(d, ec))) {
      std::fprintf(
          stderr, "rm3d init: %s is a symbolic link (init writes only inside the folder; choose a new one)\n",
          d.string().c_str());
      return 2;
    }
  }
  for (const fs::path& d : {base / "worlds", base / "behaviors", base / "lua"}) {
    fs::create_directories(d, ec);
    if (ec) {
      std::fprintf(stderr, "rm3d init: cannot make %s: %s\n", d.string().c_str(), ec.message().c_str());
      return 2;
    }
  }
  for (const auto& [path, text] : files) {
    // "x": created here or not at all (never through a link made since the check above).
    std::FILE* out = std::fopen(path.string().c_str(), "wx");
    const bool ok = out && std::fwrite(text.data(), 1, text.size(), out) == text.size();
    if (out && std::fclose(out) != 0) out = nullptr;
    if (!ok || !out) {
      std::fprintf(stderr, "rm3d init: cannot write %s: %s\n", path.string().c_str(), std::strerror(errno));
      return 2;
    }
    std::printf("wrote %s\n", path.string().c_str());
  }
  std::printf(
      "module types, lua/ and behaviours also come from %s\nnext: cd %s && rm3d run worlds/hello.lua\n",
      root.c_str(), dir.c_str());
  return 0;
}

}  // namespace rm3d
