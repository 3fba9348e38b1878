// Where rm3d finds its data (assets/modules, assets/meshes, lua/, behaviors/, worlds/): the
// project root every relative path and module type resolves against.
#pragma once

#include <string>
#include <vector>

namespace rm3d {

struct DataRoot {
  std::string path;                 ///< absolute; empty when none was found
  std::string from;                 ///< how it was found: "--root", "installed", "RM3D_ROOT", ...
  std::vector<std::string> looked;  ///< every place tried, in order, each with why it was skipped
  std::string error;                ///< when path is empty (or --root / RM3D_ROOT is not a project)
};

/// True when `dir` holds RM3D data (an assets/modules folder).
bool isDataRoot(const std::string& dir);

/// In order: `given` (--root) when not empty; then where the executable is installed
/// (<exe dir>/../share/rm3d); then $RM3D_ROOT; then the current project (the working folder or
/// the nearest parent holding assets/modules); then, for a binary still in the folder it was
/// built in, its source tree. A --root or RM3D_ROOT that is not a project is an error naming it;
/// when nothing is found, the error lists every place looked.
DataRoot findDataRoot(const std::string& given);

/// What a world says of itself, from its source: the first sentence of the comment it opens with
/// (its lines joined), at most `limit` bytes cut at a word, without a leading "worlds/x.lua:"
/// naming itself; "" when it opens with code. Any bytes in, valid UTF-8 without control
/// characters out.
std::string worldSummary(const std::string& source, size_t limit);

/// `rm3d worlds`: prints the shipped worlds (<root>/worlds/*.lua) with their first comment line.
int listWorldsCommand(const std::string& root);

/// `rm3d init DIR`: a project folder for one's own worlds and behaviours outside the checkout
/// (worlds/, behaviors/, lua/, a first world and behaviour, and a .luarc.json pointing the Lua
/// language server at `root`'s API definitions). Never overwrites a file; exit code 2 and a
/// message naming the file when one is in the way or cannot be written.
int initProjectCommand(const std::string& dir, const std::string& root);

}  // namespace rm3d
