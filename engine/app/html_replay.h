// `rm3d replay FILE --html OUT.html` and `rm3d run ... --html OUT.html`: a recording as one
// self-contained web page (engine/app/html_replay/page.html, with three.js from the Debian
// package libjs-three and the run's data inlined) that opens from disk with no server.
#pragma once

#include <cstdint>
#include <string>

#include "io/recording.h"

namespace rm3d {

struct HtmlReplayStats {
  int64_t recordedFrames = 0, keptFrames = 0;
  int stride = 1;      ///< every stride-th recorded frame is kept (and the last)
  uint64_t bytes = 0;  ///< size of the page written
};

/// At most this many pose samples (link, body and particle/cloth-node poses over all kept
/// frames); a longer or larger run keeps every n-th frame (said on the page).
constexpr int64_t kHtmlPoseBudget = 4'000'000;

/// The three.js build inlined into the page: the environment variable RM3D_THREE_JS when set,
/// else the file named at configure time (CMake RM3D_THREE_JS; Debian libjs-three's).
const char* htmlThreeJsPath();

/// Whether the three.js file can be read (checked before a run, so a long run does not end in
/// an error). False and err naming the path and the package.
bool htmlReplayReady(std::string& err);

/// Writes the page for `rec` drawn with `camera` (world.camera{} with --eye/--target/--fov
/// applied) to `out`. False and err ("--html OUT: what went wrong") on failure; the three.js
/// file missing is one (err names its path and the package).
bool writeHtmlReplay(const Recording& rec, const SceneLayout::CameraDef& camera, const std::string& out,
                     HtmlReplayStats& stats, std::string& err);

}  // namespace rm3d
