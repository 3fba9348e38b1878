// What `rm3d run` keeps of a run for pictures and recordings: the scene layout, the state at the
// start (the automatic camera frames it) and now, and the --record writer. One object per run;
// the run loop calls start() once the world is loaded, step() after every step, finish() at the end.
#pragma once

#include <string>
#include <vector>

#include "io/recording.h"
#include "io/scene_state.h"
#include "world/world.h"

namespace rm3d {

/// --eye X,Y,Z --target X,Y,Z --fov DEG as given (empty: not given), shared by run and replay.
struct CameraArgs {
  std::string eye, target, fov;
};
/// Applies the given ones over `def` (they win over world.camera{...}). False and err naming the flag.
bool applyCameraArgs(const CameraArgs& a, SceneLayout::CameraDef& def, std::string& err);

class RunCapture {
 public:
  /// `record`: the file for --record (empty: none); `meta` goes into it.
  RunCapture(std::string record, RecordingMeta meta, CameraArgs camera)
      : m_record(std::move(record)), m_meta(std::move(meta)), m_cameraArgs(std::move(camera)) {}

  /// After loading, before the first step: the layout, the start state, frame 0 of the recording.
  void start(const World& w);
  /// After a step: the state now, and a frame of the recording.
  void step(const World& w);
  /// Writes the recording's sources and end. False and err when it could not be written.
  bool finish(const std::vector<std::pair<std::string, std::string>>& sources, std::string& err);

  bool started() const { return m_started; }
  /// The picture now, and the camera for it (sceneCamera: framed at the start).
  Snapshot snapshot() const {
    Snapshot s = buildSnapshot(m_layout, m_now);
    if (m_labels) addModuleLabels(m_layout, m_now, s);
    return s;
  }
  /// --labels: pictures name every module.
  void setLabels(bool on) { m_labels = on; }
  Camera camera() const { return sceneCamera(m_layout, m_start, m_now); }
  /// Brings the state up to date without recording (the last picture of a run).
  void refresh(const World& w) { captureState(w, m_layout, m_now); }
  const SceneLayout& layout() const { return m_layout; }
  const SceneState& now() const { return m_now; }
  /// The first --record problem, or empty.
  const std::string& error() const { return m_error; }
  const RecordingWriter& writer() const { return m_writer; }
  /// Wall seconds spent recording (capturing, packing and writing frames).
  double recordSeconds() const { return m_recordSeconds; }

 private:
  std::string m_record;
  RecordingMeta m_meta;
  CameraArgs m_cameraArgs;
  bool m_started = false;
  bool m_labels = false;
  SceneLayout m_layout;
  SceneState m_start, m_now;
  RecordingWriter m_writer;
  FrameEvents m_events;
  size_t m_eventsSeen = 0;
  std::vector<std::string> m_faults;  // last fault text seen per module
  std::string m_error;
  double m_recordSeconds = 0;
};

}  // namespace rm3d
