// Dock geometry: the frame of a dock face and where a partner dock must sit to mate with it.
#pragma once

#include "core/types.h"
#include "modules/module_type.h"

namespace rm3d {

/// Dock frame in its link frame: origin at the face centre, x the outward normal, z the face's
/// `up` reference, y = z cross x.
Pose dockFrame(const DockDef& d);

/// World frame that a partner dock must have to mate face to face with a dock whose world frame
/// is `a`: normals opposite, `up` turned by orientation * 360/symmetry degrees about a's normal.
Pose matingFrame(const Pose& a, int orientation, int symmetry);

/// Gap between two dock faces (m) and the angle between their normals' opposition (rad).
struct DockError {
  double gap = 0;
  double angle = 0;
};
DockError dockError(const Pose& a, const Pose& b);

/// True when the genders can latch: male-female, or genderless with genderless.
bool gendersMate(Gender a, Gender b);

}  // namespace rm3d
