// A check that SolverWorld's fused passes over the bodies (SolverWorld::stepSimulation) give the
// same bits as Bullet's separate passes, for the unit tests (which do not see Bullet's headers).
#pragma once

#include <string>

namespace rm3d {

/// Empty when two worlds with the same bodies (a box resting on the ground, a box pushed by a
/// force every step, a still box without gravity that falls asleep; all damped) end in the same
/// bits, one stepped with the passes fused and one through Bullet's fixed-step path, which runs
/// them apart; else what differed first.
std::string fusedPassesMismatch();

}  // namespace rm3d
