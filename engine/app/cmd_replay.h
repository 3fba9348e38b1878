// `rm3d replay FILE --view`: a recording in a window (GLFW + Dear ImGui) with a time slider.
#pragma once

#include "io/recording.h"

namespace rm3d {

/// Shows the recording until the window closes; `frames` > 0 renders that many frames, saves
/// the last as `screenshot` (tests) and exits. Exit code 0, or 2 with no display.
int replayViewer(const Recording& rec, const SceneLayout::CameraDef& camera, int frames,
                 const std::string& screenshot);

}  // namespace rm3d
