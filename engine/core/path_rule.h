// The path rule: every file a script names (module-type files, behaviours, meshes, heightfield
// images, `require`d modules) is found by findScriptFile, and only there. A relative name is
// looked for in each base folder in turn (the naming script's folder first); `..` and symlinks are
// resolved, and the file must really lie inside one of the allowed folders (a world's own folder
// and the project root; for `require`, its search folders). An absolute name is allowed only
// inside those folders. A file outside is never opened, so no message can show its content.
// checkOutputsApart is the rule for what a run writes: no output overwrites an input or another
// output. docs/limits.md states both rules for users.
#pragma once

#include <string>
#include <vector>

namespace rm3d {

class SourceFiles;

struct ScriptFile {
  enum class Status { Found, Missing, Outside };
  Status status = Status::Missing;
  std::string path;  ///< Found: absolute and lexically normal; Outside: the path that left the folders
};

/// Looks `name` up as described above. `sources` (may be null) decides what exists for .lua files
/// while a fork's recorded texts are laid over the disk; those texts were checked when recorded.
ScriptFile findScriptFile(const std::string& name, const std::vector<std::string>& bases,
                          const std::vector<std::string>& allowed, const SourceFiles* sources);

/// "'NAME' lies outside the folders scripts may read files from (A/ and B/; see docs/limits.md)".
std::string outsideMessage(const std::string& name, const std::vector<std::string>& allowed);

/// A named file of one run: the flag (or "the world script") and the path as given.
struct NamedPath {
  std::string name, path;
};
/// The output-overwrite rule: no output may be one of the run's inputs, and no two outputs the
/// same file (compared after resolving `..` and symlinks, and by inode where both exist). False
/// and `err` naming both ("--json w.lua: is also the world script w.lua; ...") otherwise.
bool checkOutputsApart(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs,
                       std::string& err);

/// A world (or test folder) path as given on the command line (or to rm3d.World), resolved: `path` itself
/// when it exists from the working folder, else `<root>/<path>` when that exists (a shipped world such as
/// worlds/snake.lua, run from another folder), else `path` unchanged (the command then reports it
/// missing). `note` is set to a line saying which file is used when the data root's is, or, when
/// neither exists, where it looked.
std::string resolveWorldPath(const std::string& path, const std::string& root, std::string* note);

/// True when `p` is `dir` or lies below it (both absolute and normal; compared by components).
bool pathInside(const std::string& p, const std::string& dir);

}  // namespace rm3d
