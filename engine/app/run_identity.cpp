// The version, command line and parameters of a run, for its --json summary.
#include "app/run_identity.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/param_value.h"
#include "core/version.h"

namespace rm3d {

void addRunIdentity(nlohmann::json& summary, const std::vector<std::string>& commandLine,
                    const std::map<std::string, std::string>& params) {
  summary["version"] = rm3dVersion();
  summary["command_line"] = commandLine;
  nlohmann::json p = nlohmann::json::object();
  for (const auto& [key, text] : params) {
    const ParamValue v = parseParamValue(text);
    switch (v.kind) {
      case ParamValue::Kind::Integer:
        p[key] = v.integer;
        break;
      case ParamValue::Kind::Number:
        p[key] = std::isfinite(v.number) ? nlohmann::json(v.number) : nlohmann::json(text);
        break;
      case ParamValue::Kind::Boolean:
        p[key] = v.boolean;
        break;
      case ParamValue::Kind::String:
        p[key] = text;
        break;
    }
  }
  summary["params"] = p;
}

}  // namespace rm3d
