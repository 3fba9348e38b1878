// The run summary (`--json`, the Python API's summary()): the fields docs/command-line.md lists.
#pragma once

#include <cstdint>
#include <nlohmann/json_fwd.hpp>

namespace rm3d {

class World;

/// The world's state now as the run summary: settings, modules (pose, joints, docks, error) in
/// id order, connections, dock events, messages, failures, metrics, cloths, particles, faults and
/// the error. NaN and infinities are written as "nan", "inf", "-inf".
nlohmann::json runSummary(const World& w, double wallSeconds);

/// A 64-bit FNV-1a digest of everything that makes up the state now: the step count, every link's
/// pose and every joint's velocity (their bits), dock states, connections, dock events, message
/// counts, faults and the run summary (less its wall clock and the world file's path). Equal
/// digests after equal steps: the same run, bit for bit (at any thread count; after a restore).
uint64_t stateDigest(const World& w);

}  // namespace rm3d
