// Reads a module-type file (assets/modules/<type>.lua, format documented at the top of
// assets/modules/superbot.lua) into a ModuleTypeDef, checking every field.
#pragma once

#include <string>

#include "modules/module_type.h"

namespace rm3d {

class SourceFiles;
class MeshCache;

/// Runs `path` in a fresh sandboxed LuaVm (64 MB, 1e8 instructions; `require` searches the
/// file's folder, then projectRoot/lua) and converts the table it returns. Mesh files resolve
/// against the file's folder, then projectRoot. Throws InputError naming the file (relative to
/// projectRoot) and the place in the data, e.g.
/// "assets/modules/superbot.lua: links[2].shapes[1]: unknown key 'sise' (expected one of: ...)".
/// The result's `file` is that display path.
/// `sources` (may be null: the disk) serves the Lua texts (core/source_files.h); `meshes` (may be
/// null) keeps parsed mesh files for the next load (assets/mesh_loader.h).
ModuleTypeDef loadModuleType(const std::string& path, const std::string& projectRoot,
                             SourceFiles* sources = nullptr, MeshCache* meshes = nullptr);

}  // namespace rm3d
