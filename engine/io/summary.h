// The run summary (`--json`, the Python API's summary()): the fields docs/command-line.md lists.
#pragma once

#include <nlohmann/json_fwd.hpp>

namespace rm3d {

class World;

/// The world's state now as the run summary: settings, modules (pose, joints, docks, error) in
/// id order, connections, dock events, messages, failures, metrics, cloths, particles, faults and
/// the error. NaN and infinities are written as "nan", "inf", "-inf".
nlohmann::json runSummary(const World& w, double wallSeconds);

}  // namespace rm3d
