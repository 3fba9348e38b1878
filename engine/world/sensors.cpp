// Sensors: read lazily, once per step, from the physics state. Reads are const on the World and
// write only the reading module's own cache, so behaviours on worker threads read in parallel
// (see world/module_handle.h); ray casts are serialised inside PhysicsWorld.
#include <algorithm>
#include <cmath>

#include "docking/dock_frame.h"
#include "world/world.h"

namespace rm3d {

namespace {
constexpr double kProximityRange = 0.1;  // m: how far an IR dock sensor sees a partner
}

int World::sensorCode(int m, const std::string& name) const {
  const ModuleTypeDef& t = *m_modules[size_t(m)].type;
  const int joints = int(t.joints.size()), docks = int(t.docks.size());
  if (name.rfind("joint:", 0) == 0) {
    const int j = t.findJoint(name.substr(6));
    return j < 0 ? -1 : j;
  }
  if (name.rfind("dock:", 0) == 0) {
    const int d = t.findDock(name.substr(5));
    return d < 0 ? -1 : joints + d;
  }
  const int s = t.findSensor(name);
  return s < 0 ? -1 : joints + docks + s;
}

std::string World::sensorNames(int m) const {
  const ModuleTypeDef& t = *m_modules[size_t(m)].type;
  std::string out;
  for (const JointDef& j : t.joints) out += (out.empty() ? "joint:" : ", joint:") + j.name;
  for (const DockDef& d : t.docks) out += ", dock:" + d.name;
  for (const SensorDef& s : t.sensors) out += ", " + s.name;
  return out;
}

void World::stallJoint(int m, int joint) {
  Module& mod = m_modules[size_t(m)];
  mod.stalled[size_t(joint)] = 1;
  mod.stallAngle[size_t(joint)] = jointAngle(m, joint);
}

void World::blockDock(int m, int dock) {
  m_modules[size_t(m)].docks[size_t(dock)].latchable = false;
}

void World::killSensor(int m, int code) {
  m_modules[size_t(m)].deadSensors[size_t(code)] = 1;
}

void World::updateAccelerometers() {
  // After each physics step: acceleration of the accelerometers in use (read at least once), for
  // the specific force (a - g) they read in the next step. Unread ones cost nothing.
  for (size_t i = 0; i < m_modules.size(); ++i) {
    Module& m = m_modules[i];
    if (!m.accelInUse) continue;
    for (size_t s = 0; s < m.type->sensors.size(); ++s) {
      const SensorDef& sd = m.type->sensors[s];
      if (sd.kind != SensorKind::Accelerometer) continue;
      const int part = m.parts[size_t(sd.link)];
      const Vec3 v = m_physics->partLinearVelocity(part);
      m.accelWorld[s] = m.accelSteps > 0 ? Vec3((v - m.accelPrevVel[s]) / m_settings.dt) : Vec3::Zero();
      m.accelPrevVel[s] = v;
    }
    ++m.accelSteps;
  }
}

void World::buildProximity() const {
  std::lock_guard<std::mutex> lock(m_proximityMutex);
  if (m_proximityStep.load(std::memory_order_relaxed) == m_steps) return;
  m_proximityDocks.clear();
  for (size_t i = 0; i < m_modules.size(); ++i) {
    const Module& m = m_modules[i];
    for (size_t d = 0; d < m.docks.size(); ++d)
      if (m.docks[d].enabled && !m.docks[d].engaged)
        m_proximityDocks.push_back({int(i), int(d), dockPose(int(i), int(d))});
  }
  std::sort(m_proximityDocks.begin(), m_proximityDocks.end(), [](const FreeDock& a, const FreeDock& b) {
    return a.pose.pos.x() < b.pose.pos.x() ||
           (a.pose.pos.x() == b.pose.pos.x() &&
            (a.module < b.module || (a.module == b.module && a.dock < b.dock)));
  });
  m_proximityStep.store(m_steps, std::memory_order_release);
}

SensorReading World::readSensor(Module& m, int mi, int code, bool velocity) const {
  SensorReading r;
  if (m.deadSensors[size_t(code)]) return r;  // a dead sensor reads nil
  const ModuleTypeDef& t = *m.type;
  const int joints = int(t.joints.size()), docks = int(t.docks.size());
  if (code < joints) {
    r.kind = SensorReading::Kind::Number;
    r.v[0] = velocity ? jointVelocity(mi, code) : jointAngle(mi, code);
    return r;
  }
  auto& cached = m.sensorCache[size_t(code)];
  if (cached.first == m_steps) return cached.second;
  if (code < joints + docks) {
    const int d = code - joints;
    const DockState& st = m.docks[size_t(d)];
    r.kind = SensorReading::Kind::Dock;
    r.flag = st.enabled;
    r.engaged = st.engaged;
    if (!st.engaged) {
      // IR-style proximity: the nearest compatible free dock of another module within range.
      if (m_proximityStep.load(std::memory_order_acquire) != m_steps) {
        m_proximityWanted.store(true, std::memory_order_relaxed);
        buildProximity();
      }
      const Pose self = dockPose(mi, d);
      const Vec3& p = self.pos;
      const Gender g = t.docks[size_t(d)].gender;
      auto it = std::lower_bound(m_proximityDocks.begin(), m_proximityDocks.end(), p.x() - kProximityRange,
                                 [](const FreeDock& f, double x) { return f.pose.pos.x() < x; });
      double best = -1;
      Vec3 toward = Vec3::Zero();
      for (; it != m_proximityDocks.end() && it->pose.pos.x() <= p.x() + kProximityRange; ++it) {
        if (it->module == mi) continue;
        if (!gendersMate(g, m_modules[size_t(it->module)].type->docks[size_t(it->dock)].gender)) continue;
        const double dist = (it->pose.pos - p).norm();
        if (dist <= kProximityRange && (best < 0 || dist < best)) {
          best = dist;
          toward = it->pose.pos - p;
        }
      }
      r.proximity = best;
      // The bearing: the unit direction to that dock in this dock's frame (x its outward normal,
      // z its up reference), as the IR receivers around a real dock face give it.
      if (best > 1e-9) {
        const Vec3 b = self.rot.conjugate() * (toward / best);
        for (int k = 0; k < 3; ++k) r.v[k] = b[k];
        r.hasBearing = true;
      }
    }
  } else {
    const SensorDef& sd = t.sensors[size_t(code - joints - docks)];
    const Pose link = linkPose(mi, sd.link);
    const int part = m.parts[size_t(sd.link)];
    switch (sd.kind) {
      case SensorKind::Accelerometer: {
        m.accelInUse = true;  // from now on its link's acceleration is tracked (the first read sees none)
        const Vec3 f =
            link.rot.conjugate() * (m.accelWorld[size_t(code - joints - docks)] - m_settings.gravity);
        r.kind = SensorReading::Kind::Vector;
        for (int k = 0; k < 3; ++k) r.v[k] = f[k];
        break;
      }
      case SensorKind::Gyro: {
        const Vec3 w = link.rot.conjugate() * m_physics->partAngularVelocity(part);
        r.kind = SensorReading::Kind::Vector;
        for (int k = 0; k < 3; ++k) r.v[k] = w[k];
        break;
      }
      case SensorKind::Orientation:
        r.kind = SensorReading::Kind::Quaternion;
        r.v[0] = link.rot.w();
        r.v[1] = link.rot.x();
        r.v[2] = link.rot.y();
        r.v[3] = link.rot.z();
        break;
      case SensorKind::Position:
        r.kind = SensorReading::Kind::Vector;
        for (int k = 0; k < 3; ++k) r.v[k] = link.pos[k];
        break;
      case SensorKind::Range: {
        const Vec3 dir = link.rot * sd.dir;
        const Vec3 from = link * sd.pos + dir * sd.minRange;
        const double hit = m_physics->rayCast(from, dir, sd.maxRange - sd.minRange, mi);
        if (hit >= 0) {
          r.kind = SensorReading::Kind::Number;
          r.v[0] = hit + sd.minRange;
        }
        break;
      }
      case SensorKind::Contact:
        r.kind = SensorReading::Kind::Boolean;
        r.flag = m_physics->partTouching(part);
        break;
    }
  }
  cached = {m_steps, r};
  return r;
}

}  // namespace rm3d
