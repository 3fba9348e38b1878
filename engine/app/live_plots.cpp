// The viewer's live plots (app/live_plots.h), drawn with ImGui::PlotLines.
#include "app/live_plots.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "world/world.h"

namespace rm3d {

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr size_t kMaxSamples = 2000;  ///< per series, whatever the frame rate

/// Values as PlotLines takes them: a contiguous array, NaN (no value) as the previous value.
std::vector<float> plotted(const std::deque<float>& values, float& lo, float& hi) {
  std::vector<float> out(values.begin(), values.end());
  float last = kNaN;
  for (float& v : out) {
    if (std::isnan(v)) v = last;
    last = v;
    if (!std::isnan(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  // Leading samples without a value take the first value.
  const auto first = std::find_if(out.begin(), out.end(), [](float v) { return !std::isnan(v); });
  std::fill(out.begin(), first, first == out.end() ? 0.0f : *first);
  return out;
}

/// One plot box of one or two lines on a common scale (the second, e.g. a target, drawn over
/// the first with a transparent frame), with a caption of the latest values.
void plotBox(const char* id, const std::string& caption, const std::deque<float>& a,
             const std::deque<float>* b, float height) {
  float lo = std::numeric_limits<float>::max(), hi = -lo;
  const std::vector<float> va = plotted(a, lo, hi);
  const std::vector<float> vb = b ? plotted(*b, lo, hi) : std::vector<float>();
  if (lo > hi) lo = hi = 0;
  const float pad = std::max(1e-6f, 0.05f * (hi - lo));
  const ImVec2 size(ImGui::GetContentRegionAvail().x, height);
  const ImVec2 at = ImGui::GetCursorPos();
  ImGui::PushStyleColor(ImGuiCol_PlotLines, ImVec4(0.45f, 0.75f, 1.0f, 1.0f));
  ImGui::PlotLines(id, va.data(), int(va.size()), 0, caption.c_str(), lo - pad, hi + pad, size);
  ImGui::PopStyleColor();
  if (b && !vb.empty()) {
    const ImVec2 after = ImGui::GetCursorPos();
    ImGui::SetCursorPos(at);
    ImGui::PushStyleColor(ImGuiCol_FrameBg, ImVec4(0, 0, 0, 0));
    ImGui::PushStyleColor(ImGuiCol_PlotLines, ImVec4(1.0f, 0.75f, 0.2f, 0.9f));
    const std::string id2 = std::string(id) + "_b";
    ImGui::PlotLines(id2.c_str(), vb.data(), int(vb.size()), 0, nullptr, lo - pad, hi + pad, size);
    ImGui::PopStyleColor(2);
    ImGui::SetCursorPos(after);
  }
}

std::string latest(const char* format, const std::deque<float>& values) {
  char text[64] = "-";
  if (!values.empty() && !std::isnan(values.back())) std::snprintf(text, sizeof text, format, values.back());
  return text;
}

}  // namespace

void LivePlots::clear() {
  m_times.clear();
  m_joints.clear();
  m_traces.clear();
  m_lastStep = -1;
}

void LivePlots::sample(const World& w, int module) {
  if (module != m_module || &w != m_world || w.steps() < m_lastStep) {
    clear();
    m_module = module;
    m_world = &w;
  }
  if (module < 0 || module >= int(w.modules().size()) || w.steps() == m_lastStep) return;
  m_lastStep = w.steps();
  const Module& m = w.module(module);
  if (m_joints.empty())
    for (const JointDef& j : m.type->joints)
      for (const char* what : {"angle", "target", "torque"}) m_joints.push_back({j.name + " " + what, {}});
  for (size_t s = m_traces.size(); s < m.traces.names.size(); ++s) {
    // A series first recorded now has no values before: pad it to the others' length.
    m_traces.push_back({m.traces.names[s], std::deque<float>(m_times.size(), kNaN)});
  }
  m_times.push_back(w.time());
  for (size_t j = 0; j < m.type->joints.size(); ++j) {
    const JointCommand& c = m.commands[j];
    m_joints[3 * j].values.push_back(float(w.jointAngle(module, int(j))));
    m_joints[3 * j + 1].values.push_back(c.mode == JointMode::Servo ? float(c.value) : kNaN);
    m_joints[3 * j + 2].values.push_back(float(w.jointTorque(module, int(j))));
  }
  for (size_t s = 0; s < m_traces.size(); ++s) m_traces[s].values.push_back(float(m.traces.values[s]));
  // Keep the window (and at most kMaxSamples).
  while (!m_times.empty() && (m_times.front() < w.time() - kWindow || m_times.size() > kMaxSamples)) {
    m_times.pop_front();
    for (Series& s : m_joints) s.values.pop_front();
    for (Series& s : m_traces) s.values.pop_front();
  }
}

void LivePlots::draw() const {
  if (m_times.empty()) {
    ImGui::TextDisabled("(no steps yet)");
    return;
  }
  ImGui::TextDisabled("last %.1f s; angle (blue) against target (orange), rad",
                      m_times.back() - m_times.front());
  for (size_t j = 0; j + 2 < m_joints.size(); j += 3) {
    const std::string name = m_joints[j].label.substr(0, m_joints[j].label.size() - 6);  // drop " angle"
    ImGui::PushID(int(j));
    plotBox(
        "##angle",
        name + ": " + latest("%+.3f", m_joints[j].values) + " -> " + latest("%+.3f", m_joints[j + 1].values),
        m_joints[j].values, &m_joints[j + 1].values, 48);
    plotBox("##torque", name + " torque " + latest("%+.3f", m_joints[j + 2].values) + " N m",
            m_joints[j + 2].values, nullptr, 32);
    ImGui::PopID();
  }
  for (size_t s = 0; s < m_traces.size(); ++s) {
    ImGui::PushID(int(1000 + s));
    plotBox("##trace", "trace." + m_traces[s].label + " " + latest("%.4g", m_traces[s].values),
            m_traces[s].values, nullptr, 40);
    ImGui::PopID();
  }
}

}  // namespace rm3d
