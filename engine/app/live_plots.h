// The viewer inspector's live plots: for the selected module, each joint's angle against its
// servo target and its torque, and every series its behaviour records with module.trace, over
// the last few seconds of simulated time. Sampled once per drawn frame (when the world moved),
// so at high speed the plots thin out rather than slow the window down.
#pragma once

#include <deque>
#include <string>
#include <vector>

namespace rm3d {

class World;

class LivePlots {
 public:
  /// Simulated seconds shown.
  static constexpr double kWindow = 5.0;
  /// Samples the module's state if the world stepped since the last sample. A new module, or a
  /// clock that went back (a rebuilt world), starts the plots afresh.
  void sample(const World& w, int module);
  /// Draws the plots (Dear ImGui, inside the inspector window).
  void draw() const;

 private:
  struct Series {
    std::string label;
    std::deque<float> values;  ///< NaN: no value (a joint not in servo mode has no target)
  };
  void clear();
  int m_module = -1;
  const World* m_world = nullptr;
  long long m_lastStep = -1;
  std::deque<double> m_times;
  std::vector<Series> m_joints;  ///< 3 per joint: angle, target, torque
  std::vector<Series> m_traces;  ///< per module.trace slot
};

}  // namespace rm3d
