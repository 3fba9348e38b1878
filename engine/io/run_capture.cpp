#include "io/run_capture.h"

#include <chrono>
#include <cmath>
#include <cstdio>

namespace rm3d {

namespace {

bool parseVec(const std::string& flag, const std::string& text, Vec3& out, std::string& err) {
  double x = 0, y = 0, z = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf%c", &x, &y, &z, &tail) != 3 || !std::isfinite(x) ||
      !std::isfinite(y) || !std::isfinite(z) || std::abs(x) > 1e6 || std::abs(y) > 1e6 || std::abs(z) > 1e6) {
    err = flag + " " + text + ": expected three numbers X,Y,Z in metres, e.g. 1.5,-1.5,1";
    return false;
  }
  out = Vec3(x, y, z);
  return true;
}

}  // namespace

bool applyCameraArgs(const CameraArgs& a, SceneLayout::CameraDef& def, std::string& err) {
  Vec3 v;
  if (!a.eye.empty()) {
    if (!parseVec("--eye", a.eye, v, err)) return false;
    def.eye = v;
    def.follow = -1;
  }
  if (!a.target.empty()) {
    if (!parseVec("--target", a.target, v, err)) return false;
    def.target = v;
    def.follow = -1;
  }
  if (!a.fov.empty()) {
    char* end = nullptr;
    const double f = std::strtod(a.fov.c_str(), &end);
    if (end == a.fov.c_str() || *end != '\0' || !(f >= 1 && f <= 170)) {
      err = "--fov " + a.fov + ": expected a vertical field of view in degrees, from 1 to 170";
      return false;
    }
    def.fovDeg = f;
  }
  if (def.eye && def.target && (*def.eye - *def.target).norm() < 1e-9) {
    err = "--eye and --target: the camera needs its eye apart from its target";
    return false;
  }
  return true;
}

void RunCapture::start(const World& w) {
  m_layout = sceneLayout(w);
  std::string err;
  applyCameraArgs(m_cameraArgs, m_layout.camera, err);  // checked by the command before the run
  captureState(w, m_layout, m_start);
  m_now = m_start;
  m_faults.assign(w.modules().size(), std::string());
  m_eventsSeen = w.events().size();
  m_started = true;
  if (m_record.empty()) return;
  if (!m_meta.seedGiven) m_meta.seed = w.settings().seed;
  m_meta.dt = w.settings().dt;
  if (!m_writer.open(m_record, m_meta, m_layout, m_error)) return;
  // Frame 0 lists the connections made while the world was built as "engaged" events, so a
  // reader knows the connection graph from the start (the dock flags alone do not pair docks).
  for (const Connection& c : w.connections())
    m_events.docks.push_back({c.time, DockEventKind::Engaged, c.moduleA, c.dockA, c.moduleB, c.dockB});
  m_writer.frame(m_now, m_events);
  m_events.docks.clear();
}

void RunCapture::step(const World& w) {
  if (!m_started) return;
  const auto t0 = std::chrono::steady_clock::now();
  captureState(w, m_layout, m_now);
  if (!m_writer.isOpen()) return;
  m_events.docks.clear();
  m_events.faults.clear();
  const std::vector<DockEvent>& events = w.events();
  for (; m_eventsSeen < events.size(); ++m_eventsSeen) m_events.docks.push_back(events[m_eventsSeen]);
  for (size_t i = 0; i < m_faults.size() && i < w.modules().size(); ++i) {
    const std::string& fault = w.modules()[i].fault;
    if (fault == m_faults[i]) continue;
    m_faults[i] = fault;
    if (!fault.empty()) m_events.faults.emplace_back(int(i), fault);
  }
  m_writer.frame(m_now, m_events);
  m_recordSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool RunCapture::finish(const std::vector<std::pair<std::string, std::string>>& sources, std::string& err) {
  if (!m_error.empty()) {
    err = m_error;
    return false;
  }
  return m_writer.finish(sources, err);
}

}  // namespace rm3d
