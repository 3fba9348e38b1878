#include "core/path_rule.h"

#include <algorithm>
#include <filesystem>

#include "core/source_files.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

fs::path normalAbsolute(const fs::path& p) {
  return SourceFiles::key(p.string());
}

/// The folder with symlinks resolved (as it is when it does not exist).
fs::path realFolder(const std::string& dir) {
  std::error_code ec;
  const fs::path r = fs::weakly_canonical(normalAbsolute(dir), ec);
  return ec ? normalAbsolute(dir) : r;
}

bool insideAny(const fs::path& p, const std::vector<std::string>& allowed, bool real) {
  return std::any_of(allowed.begin(), allowed.end(), [&](const std::string& dir) {
    return pathInside(p.string(), (real ? realFolder(dir) : normalAbsolute(dir)).string());
  });
}

}  // namespace

bool pathInside(const std::string& p, const std::string& dir) {
  const fs::path pp(p), dp(dir);
  auto d = dp.begin(), q = pp.begin();
  for (; d != dp.end(); ++d, ++q) {
    if (d->empty() && std::next(d) == dp.end()) return true;  // a trailing separator
    if (q == pp.end() || *q != *d) return false;
  }
  return true;
}

ScriptFile findScriptFile(const std::string& name, const std::vector<std::string>& bases,
                          const std::vector<std::string>& allowed, const SourceFiles* sources) {
  ScriptFile out;
  const fs::path given(name);
  std::vector<fs::path> candidates;
  if (given.is_absolute())
    candidates.push_back(given.lexically_normal());
  else
    for (const std::string& b : bases) candidates.push_back(normalAbsolute(fs::path(b) / given));
  std::string outside;
  for (const fs::path& c : candidates) {
    // Named outside the folders (an absolute path, or `..` climbing out): never looked at, so a
    // script cannot even probe for files there.
    if (!insideAny(c, allowed, false)) {
      if (outside.empty()) outside = c.string();
      continue;
    }
    const bool overlay = sources && sources->overlayOn() && c.extension() == ".lua";
    std::error_code ec;
    if (overlay ? !sources->isFile(c.string()) : !fs::exists(c, ec)) continue;
    // It exists: where it really lies (a symlink may lead out). Recorded texts were checked then.
    const fs::path real = fs::weakly_canonical(c, ec);
    if (!(overlay && sources->overlaid(c.string())) &&
        (ec || !insideAny(real, allowed, true) || (sources && !sources->diskAllowed(real.string())))) {
      out.status = ScriptFile::Status::Outside;
      out.path = c.string();
      return out;
    }
    out.status = ScriptFile::Status::Found;
    out.path = c.string();
    return out;
  }
  if (!outside.empty()) {
    out.status = ScriptFile::Status::Outside;
    out.path = outside;
  }
  return out;
}

namespace {

bool samePath(const std::string& a, const std::string& b) {
  std::error_code ec1, ec2;
  if (fs::exists(a, ec1) && fs::exists(b, ec2)) return fs::equivalent(a, b, ec1) && !ec1;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec1), ec1);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec2), ec2);
  return ca.lexically_normal() == cb.lexically_normal();
}
}  // namespace

bool checkOutputsApart(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs,
                       std::string& err) {
  for (size_t i = 0; i < outputs.size(); ++i) {
    const NamedPath& o = outputs[i];
    if (o.path.empty()) continue;
    for (const NamedPath& in : inputs)
      if (!in.path.empty() && samePath(o.path, in.path)) {
        err = o.name + " " + o.path + ": is also " + in.name + " " + in.path +
              " (an output may not overwrite an input of the same run; write it elsewhere)";
        return false;
      }
    for (size_t j = 0; j < i; ++j)
      if (!outputs[j].path.empty() && samePath(o.path, outputs[j].path)) {
        err = o.name + " " + o.path + ": is also the output of " + outputs[j].name + " " + outputs[j].path +
              " (each output needs its own file)";
        return false;
      }
  }
  return true;
}

std::string outsideMessage(const std::string& name, const std::vector<std::string>& allowed) {
  std::string dirs;
  for (size_t i = 0; i < allowed.size(); ++i)
    dirs += (i == 0                    ? ""
             : i + 1 == allowed.size() ? " and "
                                       : ", ") +
            (normalAbsolute(allowed[i]) / "").string();
  return "'" + name + "' lies outside the folders scripts may read files from (" + dirs +
         "; see docs/limits.md, the path rule)";
}

std::string resolveWorldPath(const std::string& path, const std::string& root, std::string* note) {
  std::error_code ec;
  if (path.empty() || fs::exists(path, ec) || fs::path(path).is_absolute() || root.empty()) return path;
  const fs::path inRoot = fs::path(root) / path;
  if (!fs::exists(inRoot, ec)) {
    if (note)
      *note = path + ": not found in the working folder (" + fs::current_path(ec).string() +
              ") nor in the data root (" + root + "); `rm3d worlds` lists the shipped worlds";
    return path;
  }
  const std::string found = inRoot.lexically_normal().string();
  if (note) *note = path + ": not found here; using " + found + " (the data root's)";
  return found;
}

}  // namespace rm3d
