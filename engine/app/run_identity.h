// What identifies a run in its --json summary, beside the world's own fields: the version, the
// command line and the --param values (the seed is the summary's "seed"), so a result can be
// traced back to how it was made and sweeps can group results by parameter.
#pragma once

#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace rm3d {

/// Sets "version" (rm3dVersion()), "command_line" (the arguments as given, an array) and
/// "params" (key: value, typed as the world script's `args` sees them).
void addRunIdentity(nlohmann::json& summary, const std::vector<std::string>& commandLine,
                    const std::map<std::string, std::string>& params);

}  // namespace rm3d
