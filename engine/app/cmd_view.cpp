// `rm3d view`: steps a world in real time in a GLFW window (OpenGL 3.3 core) drawn by the shared
// SceneRenderer, with an orbit camera, click-to-inspect modules (Dear ImGui panels), pause /
// single step / speed / reset keys, and hot reload of behaviours, lua/ and the world file as in
// `run --watch`. `--exit-after N --screenshot FILE` renders N frames, saves the last and exits (tests,
// README pictures).
#include "app/cmd_view.h"

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <set>

#include "app/app.h"
#include "app/live_plots.h"
#include "app/orbit_camera.h"
#include "app/run_world.h"
#include "app/world_session.h"
#include "core/error.h"
#include "io/scene_state.h"
#include "io/world_snapshot.h"
#include "render/picking.h"
#include "render/scene_renderer.h"
#include "render/view_math.h"
#include "world/world.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kWindowWidth = 1280, kWindowHeight = 720;
constexpr double kMinSpeed = 0.125, kMaxSpeed = 8.0;
constexpr auto kWatchInterval = std::chrono::milliseconds(100);
// At most this much wall time per frame goes to stepping; beyond it the simulation falls behind
// real time (the status line shows it) instead of the window freezing.
constexpr double kStepBudgetSeconds = 0.05;
constexpr float kInspectorWidth = 420;
constexpr double kClickSlopPixels = 4.0;  // a press that moves less than this is a click, not a drag
const ImVec4 kErrorColor(1.0f, 0.35f, 0.3f, 1.0f);

const char* const kNoDisplayHint =
    "for pictures without a display use `rm3d run WORLD --png out.png` or `--video out.mp4`";

void* glfwProc(const char* name) {
  return reinterpret_cast<void*>(glfwGetProcAddress(name));
}

std::string glfwLastError() {
  const char* desc = nullptr;
  glfwGetError(&desc);
  return desc ? desc : "unknown GLFW error";
}

double deg(double rad) {
  return rad * 180.0 / kPi;
}

/// Colour statistics of a screenshot: pixels whose hue matches a module link colour as the
/// renderer shades it, and how many of those a pick ray through the pixel finds on a module.
struct PixelStats {
  int modulePixels = 0, picked = 0;
};

PixelStats countModulePixels(const World& w, const Snapshot& snap, const Camera& cam, int width, int height,
                             const std::vector<uint8_t>& rgba) {
  // The mesh shader outputs pow(colour * light, 1/2.2) with one scalar light factor, so a lit or
  // shadowed face keeps the channel ratios of pow(colour, 1/2.2): compare those, not values.
  std::vector<Eigen::Vector3f> hues;
  std::set<const ModuleTypeDef*> types;
  for (const Module& m : w.modules()) types.insert(m.type);
  for (const ModuleTypeDef* t : types)
    for (const LinkDef& l : t->links) {
      Eigen::Vector3f c(std::pow(l.color[0], 1 / 2.2f), std::pow(l.color[1], 1 / 2.2f),
                        std::pow(l.color[2], 1 / 2.2f));
      // Greys cannot be told from the ground and sky by hue.
      if (c.maxCoeff() - c.minCoeff() < 0.15f * c.maxCoeff()) continue;
      hues.push_back(c / c.maxCoeff());
    }
  PixelStats st;
  if (hues.empty()) return st;
  const Picker picker(snap);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const uint8_t* p = rgba.data() + (size_t(y) * width + x) * 4;
      const float top = float(std::max({p[0], p[1], p[2]}));
      if (top < 40) continue;  // too dark to judge a hue
      const Eigen::Vector3f q(p[0] / top, p[1] / top, p[2] / top);
      const bool match = std::any_of(hues.begin(), hues.end(), [&](const Eigen::Vector3f& h) {
        return (q - h).cwiseAbs().maxCoeff() < 0.08f;
      });
      if (!match) continue;
      ++st.modulePixels;
      const PickHit hit = picker.pick(pixelRay(cam, width, height, x + 0.5f, y + 0.5f));
      if (hit.item >= 0 && snap.items[size_t(hit.item)].tag >= 0) ++st.picked;
    }
  return st;
}

/// A component's colour (linear RGBA), the graph panel's and the 3D view's: ten distinct hues,
/// then round again.
std::array<float, 4> componentColour(int c) {
  static constexpr float kPalette[10][3] = {
      {0.12f, 0.47f, 0.71f}, {1.0f, 0.5f, 0.05f},   {0.17f, 0.63f, 0.17f}, {0.84f, 0.15f, 0.16f},
      {0.58f, 0.4f, 0.74f},  {0.55f, 0.34f, 0.29f}, {0.89f, 0.47f, 0.76f}, {0.5f, 0.5f, 0.5f},
      {0.74f, 0.74f, 0.13f}, {0.09f, 0.75f, 0.81f}};
  const float* p = kPalette[size_t(c) % 10];
  return {p[0], p[1], p[2], 1.0f};
}

class Viewer {
 public:
  Viewer(const ViewArgs& args, RunOptions options)
      : m_args(args), m_session(args.world, std::move(options), kWatchInterval) {}

  /// Loads the world before any window opens, so a bad file is reported like `run` does.
  bool loadInitial(std::string& err) {
    if (!m_session.load()) {
      err = m_session.worldError();
      return false;
    }
    m_world = &m_session.world();
    m_orbit = OrbitCamera::from(worldCamera(*m_world));
    m_graph = m_args.graph;
    m_components = m_args.components;
    if (m_world->camera().follow >= 0) {
      m_follow = true;
      m_followModule = m_world->camera().follow;
    }
    if (m_args.select >= 0) {
      m_selected = indexOfId(m_args.select);
      if (m_selected < 0) {
        err = "--select " + std::to_string(m_args.select) + ": no module has that id";
        return false;
      }
    }
    return true;
  }

  int run(GLFWwindow* window);

 private:
  // --- world lifetime ---
  /// After R or an edited world file (WorldSession::rebuild/poll): the new world takes over the
  /// selection and the followed module by id; a rejected file keeps the previous world running
  /// and shows why until a later save fixes it.
  void applyChanges(const SessionChanges& c, const char* why) {
    if (!c.worldError.empty())
      std::fprintf(stderr, "rm3d view: %s (fix it and save; the previous world keeps running)\n",
                   c.worldError.c_str());
    if (c.rebuilt) {
      const int selectedId = m_selected >= 0 ? m_world->module(m_selected).id : -1;
      const int followId = m_followModule >= 0 ? m_world->module(m_followModule).id : -1;
      m_world = &m_session.world();
      m_selected = indexOfId(selectedId);
      m_followModule = indexOfId(followId);
      if (m_followModule < 0) m_follow = false;
      m_owed = 0;
      m_rtfSamples.clear();
      m_pausedAtEnd = false;
      std::printf("%s: rebuilt %s (%zu modules)\n", why, m_args.world.c_str(), m_world->modules().size());
    }
    for (const SessionChanges::Rejected& r : c.rejected)
      std::fprintf(stderr, "rm3d view: reload rejected, old code keeps running: %s\n", r.error.c_str());
    for (const SessionChanges::Reload& r : c.reloaded)
      std::printf("reloaded %s into %d modules at t=%.2f s\n", r.file.c_str(), r.modules, m_world->time());
    if (!c.empty()) std::fflush(stdout);
  }

  void rebuild(const char* why) { applyChanges(m_session.rebuild(), why); }

  int indexOfId(int id) const {
    if (id < 0) return -1;
    const auto& ms = m_world->modules();
    for (size_t i = 0; i < ms.size(); ++i)
      if (ms[i].id == id) return int(i);
    return -1;
  }

  // --- hot reload ---
  void watch() { applyChanges(m_session.poll(), "world script changed"); }

  // --- time ---
  void advance(double wallDt) {
    World& w = *m_world;
    const double dt = w.settings().dt;
    if (w.stopped()) {
      m_owed = 0;
      return;
    }
    // Stop once at the world's duration, where its last checks ran; Space runs on past it.
    if (w.finished() && !m_pausedAtEnd) {
      m_pausedAtEnd = true;
      m_paused = true;
    }
    if (m_paused) {
      m_owed = 0;
      if (m_stepRequests > 0) {
        w.step();
        --m_stepRequests;
      }
      return;
    }
    m_stepRequests = 0;
    // Owe simulated time in step with the wall clock (times the speed), but never more than a few
    // frames' worth, so a stall (a dragged window, a slow reload) does not replay as a burst.
    m_owed = std::min(m_owed + wallDt * m_speed, std::max(0.25 * m_speed, 2 * dt));
    const auto start = Clock::now();
    while (m_owed >= dt && !w.stopped()) {
      w.step();
      m_owed -= dt;
      if (w.finished() && !m_pausedAtEnd) {
        m_pausedAtEnd = m_paused = true;
        m_owed = 0;
        break;
      }
      if (std::chrono::duration<double>(Clock::now() - start).count() > kStepBudgetSeconds) {
        m_owed = 0;  // slower than asked: fall behind rather than freeze the window
        break;
      }
    }
  }

  double realTimeFactor() {
    const double now = std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
    m_rtfSamples.emplace_back(now, m_world->time());
    while (m_rtfSamples.size() > 2 && now - m_rtfSamples.front().first > 1.0) m_rtfSamples.pop_front();
    const auto& [t0, s0] = m_rtfSamples.front();
    return now - t0 > 1e-3 ? (m_world->time() - s0) / (now - t0) : 0.0;
  }

  // --- input (GLFW callbacks; ImGui's own callbacks run first and chain to these) ---
  static Viewer& of(GLFWwindow* w) { return *static_cast<Viewer*>(glfwGetWindowUserPointer(w)); }

  static void onChar(GLFWwindow* w, unsigned int c) {
    if (!ImGui::GetIO().WantCaptureKeyboard) of(w).command(c);
  }
  static void onKey(GLFWwindow* w, int key, int, int action, int) {
    if (ImGui::GetIO().WantCaptureKeyboard || action == GLFW_RELEASE) return;
    Viewer& v = of(w);
    if (key == GLFW_KEY_ESCAPE) v.m_quit = true;
    if (key == GLFW_KEY_RIGHT) v.command('s');
  }
  static void onButton(GLFWwindow* w, int button, int action, int) {
    Viewer& v = of(w);
    double x = 0, y = 0;
    glfwGetCursorPos(w, &x, &y);
    if (action == GLFW_PRESS) {
      if (ImGui::GetIO().WantCaptureMouse || v.m_dragButton >= 0) return;
      v.m_dragButton = button;
      v.m_pressX = v.m_lastX = x;
      v.m_pressY = v.m_lastY = y;
      v.m_dragged = false;
    } else if (button == v.m_dragButton) {
      v.m_dragButton = -1;
      if (button == GLFW_MOUSE_BUTTON_LEFT && !v.m_dragged) v.pick(w, x, y);
    }
  }
  static void onCursor(GLFWwindow* w, double x, double y) {
    Viewer& v = of(w);
    if (v.m_dragButton < 0) return;
    if (std::hypot(x - v.m_pressX, y - v.m_pressY) > kClickSlopPixels) v.m_dragged = true;
    const float dx = float(x - v.m_lastX), dy = float(y - v.m_lastY);
    v.m_lastX = x;
    v.m_lastY = y;
    if (!v.m_dragged) return;
    int width = 0, height = 0;
    glfwGetWindowSize(w, &width, &height);
    if (v.m_dragButton == GLFW_MOUSE_BUTTON_LEFT) {
      v.m_orbit.orbit(dx, dy);
    } else {
      v.m_orbit.pan(dx, dy, height);
      v.m_follow = false;  // panning away from a followed module means: stop following
    }
  }
  static void onScroll(GLFWwindow* w, double, double dy) {
    if (!ImGui::GetIO().WantCaptureMouse) of(w).m_orbit.zoom(float(dy));
  }

  void command(unsigned int c) {
    switch (c) {
      case ' ':
        m_paused = !m_paused;
        break;
      case 's':
      case 'S':
        if (m_paused) ++m_stepRequests;
        break;
      case 'r':
      case 'R':
        rebuild("reset");
        break;
      case '+':
      case '=':
        m_speed = std::min(m_speed * 2, kMaxSpeed);
        break;
      case '-':
      case '_':
        m_speed = std::max(m_speed / 2, kMinSpeed);
        break;
      case 'f':
      case 'F':
        if (m_follow)
          m_follow = false;
        else if (m_selected >= 0)
          m_follow = true, m_followModule = m_selected;
        else
          m_notice = "select a module (click it) to follow it";
        break;
      case 'g':
      case 'G':
        m_graph = !m_graph;
        break;
      case 'c':
      case 'C':
        m_components = !m_components;
        break;
      case 'q':
      case 'Q':
        m_quit = true;
        break;
      default:
        break;
    }
  }

  /// A click: the nearest item under the cursor in the frame on screen; a module selects it
  /// (and opens the inspector), anything else clears the selection.
  void pick(GLFWwindow* w, double x, double y) {
    int width = 0, height = 0;
    glfwGetWindowSize(w, &width, &height);
    if (width <= 0 || height <= 0) return;
    const PickHit hit = Picker(m_snapshot).pick(pixelRay(m_camera, width, height, float(x), float(y)));
    const int tag = hit.item >= 0 ? m_snapshot.items[size_t(hit.item)].tag : -1;
    m_selected = tag >= 0 && tag < int(m_world->modules().size()) ? tag : -1;
  }

  // --- drawing ---
  /// The world's snapshot plus a box around the selected module; the status is ImGui's.
  void buildFrame() {
    const SceneLayout layout = sceneLayout(*m_world);
    SceneState state;
    captureState(*m_world, layout, state);
    m_snapshot = buildSnapshot(layout, state);
    m_snapshot.overlay.clear();
    m_componentOf.assign(m_world->modules().size(), 0);
    const std::vector<std::vector<int>> comps = m_world->components();
    for (size_t c = 0; c < comps.size(); ++c)
      for (int m : comps[c]) m_componentOf[size_t(m)] = int(c);
    m_componentCount = int(comps.size());
    // Module links (not dock faces, which keep their state colours) in their component's colour.
    if (m_components)
      for (size_t i = 0; i < layout.items.size() && i < m_snapshot.items.size(); ++i) {
        RenderItem& it = m_snapshot.items[i];
        if (layout.items[i].kind == SceneLayout::Kind::Link && it.tag >= 0)
          it.color = componentColour(m_componentOf[size_t(it.tag)]);
      }
    if (m_follow && m_followModule >= 0 && m_followModule < int(m_world->modules().size()))
      m_orbit.target = m_world->modulePose(m_followModule).pos.cast<float>();
    m_camera = m_orbit.camera();
    if (m_selected < 0) return;
    Eigen::AlignedBox3f box;
    for (const RenderItem& it : m_snapshot.items) {
      if (it.tag != m_selected || it.mesh < 0 || it.mesh >= int(m_snapshot.meshes.size())) continue;
      for (const Eigen::Vector3f& v : m_snapshot.meshes[size_t(it.mesh)].vertices)
        box.extend((it.transform * v.homogeneous()).head<3>());
    }
    if (box.isEmpty()) return;
    box.extend(box.min() - Eigen::Vector3f::Constant(0.005f));
    box.extend(box.max() + Eigen::Vector3f::Constant(0.005f));
    for (int a = 0; a < 8; ++a)
      for (int axis = 0; axis < 3; ++axis) {
        const int b = a | (1 << axis);  // each edge once: from a corner without the bit to one with it
        if (b == a) continue;
        RenderLine l;
        l.a = box.corner(Eigen::AlignedBox3f::CornerType(a));
        l.b = box.corner(Eigen::AlignedBox3f::CornerType(b));
        l.color = {1.0f, 0.95f, 0.3f, 1.0f};
        m_snapshot.lines.push_back(l);
      }
  }

  void drawStatus(double rtf) {
    const World& w = *m_world;
    ImGui::SetNextWindowPos(ImVec2(8, 8));
    ImGui::SetNextWindowBgAlpha(0.6f);
    ImGui::Begin("status", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                     ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav |
                     ImGuiWindowFlags_NoSavedSettings);
    const char* state = w.stopped() ? "STOPPED"
                        : m_paused && m_pausedAtEnd && w.finished()
                            ? "PAUSED at the world's duration (Space runs on)"
                        : m_paused ? "PAUSED"
                                   : "running";
    ImGui::Text("t = %.2f s   %.2fx real time   %zu modules   %d faults   %s   speed %gx%s", w.time(),
                m_paused ? 0.0 : rtf, w.modules().size(), w.faultCount(), state, m_speed,
                m_follow ? "   following" : "");
    if (!w.failures().empty())
      ImGui::TextColored(kErrorColor, "%zu failed expectations", w.failures().size());
    // The keys in the text colour: the disabled grey was hard to read on the HUD's grey.
    ImGui::TextUnformatted(
        "Space pause  S step  R reset  +/- speed  F follow  G graph  C colour components  click: inspect  "
        "Esc quit");
    if (!m_notice.empty()) ImGui::TextUnformatted(m_notice.c_str());
    ImGui::End();
  }

  /// Red panel: a rejected world file, rejected behaviour edits (file:line), a world-script
  /// error, failed expectations.
  void drawErrors(int width, int height) {
    const World& w = *m_world;
    const std::string& worldError = m_session.worldError();
    const std::map<std::string, std::string>& reloadErrors = m_session.reloadErrors();
    if (worldError.empty() && reloadErrors.empty() && w.scriptError().empty() && w.failures().empty()) return;
    ImGui::SetNextWindowPos(ImVec2(8, float(height) - 8), ImGuiCond_Always, ImVec2(0, 1));
    ImGui::SetNextWindowSizeConstraints(ImVec2(200, 0), ImVec2(float(width) * 0.6f, float(height) * 0.4f));
    ImGui::PushStyleColor(ImGuiCol_WindowBg, ImVec4(0.25f, 0.02f, 0.02f, 0.9f));
    ImGui::Begin("Errors", nullptr, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings);
    ImGui::PushStyleColor(ImGuiCol_Text, kErrorColor);
    ImGui::PushTextWrapPos(float(width) * 0.58f);
    if (!worldError.empty())
      ImGui::Text("world file rejected (the previous world keeps running):\n%s", worldError.c_str());
    for (const auto& [file, text] : reloadErrors)
      ImGui::Text("reload rejected, old code keeps running:\n%s", text.c_str());
    if (!w.scriptError().empty()) ImGui::Text("world script error: %s", w.scriptError().c_str());
    for (const Failure& f : w.failures()) ImGui::Text("FAILED at t=%.3f: %s", f.time, f.message.c_str());
    ImGui::PopTextWrapPos();
    ImGui::PopStyleColor();
    ImGui::End();
    ImGui::PopStyleColor();
  }

  /// The connection graph: a node per module where its root is seen from above (fitted to the
  /// panel), an edge per connection, nodes coloured by component; a click selects a module; below
  /// it the connections and the latest dock events.
  void drawGraph(int width, int height) {
    if (!m_graph) return;
    const World& w = *m_world;
    const float panelW = 360, canvasH = 240;
    ImGui::SetNextWindowPos(ImVec2(8, float(height) - 8), ImGuiCond_Appearing, ImVec2(0, 1));
    ImGui::SetNextWindowSize(ImVec2(panelW, std::min(canvasH + 230, float(height) * 0.6f)),
                             ImGuiCond_Appearing);
    bool open = true;
    ImGui::Begin("Connection graph (G)", &open, ImGuiWindowFlags_NoSavedSettings);
    ImGui::Text("%zu connections, %d component%s", w.connections().size(), m_componentCount,
                m_componentCount == 1 ? "" : "s");
    ImGui::Checkbox("colour the modules by component (C)", &m_components);
    const ImVec2 origin = ImGui::GetCursorScreenPos();
    const float cw = std::max(120.0f, ImGui::GetContentRegionAvail().x);
    ImGui::InvisibleButton("graph", ImVec2(cw, canvasH));
    const bool clicked = ImGui::IsItemClicked();
    ImDrawList* dl = ImGui::GetWindowDrawList();
    dl->AddRectFilled(origin, ImVec2(origin.x + cw, origin.y + canvasH), IM_COL32(250, 250, 252, 255));
    const size_t n = w.modules().size();
    std::vector<ImVec2> at(n);
    Eigen::AlignedBox2f box;
    for (size_t i = 0; i < n; ++i) box.extend(w.modulePose(int(i)).pos.head<2>().cast<float>());
    const Eigen::Vector2f size = box.isEmpty() ? Eigen::Vector2f(1, 1) : box.sizes();
    // Room on the right for the names beside the nodes.
    const float scale =
        std::min((cw - 96) / std::max(size.x(), 1e-3f), (canvasH - 32) / std::max(size.y(), 1e-3f));
    const Eigen::Vector2f mid =
        box.isEmpty() ? Eigen::Vector2f(Eigen::Vector2f::Zero()) : Eigen::Vector2f(box.center());
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2f p = w.modulePose(int(i)).pos.head<2>().cast<float>();
      at[i] = ImVec2(origin.x + cw / 2 - 36 + (p.x() - mid.x()) * scale,
                     origin.y + canvasH / 2 - (p.y() - mid.y()) * scale);
    }
    for (const Connection& c : w.connections())
      dl->AddLine(at[size_t(c.moduleA)], at[size_t(c.moduleB)], IM_COL32(40, 40, 40, 255), 2.0f);
    const float r = n > 200 ? 2.5f : n > 40 ? 4.0f : 6.0f;
    for (size_t i = 0; i < n; ++i) {
      const std::array<float, 4> c = componentColour(i < m_componentOf.size() ? m_componentOf[i] : 0);
      dl->AddCircleFilled(at[i], int(i) == m_selected ? r + 3 : r,
                          ImGui::ColorConvertFloat4ToU32(ImVec4(c[0], c[1], c[2], 1)));
      if (n <= 40)
        dl->AddText(ImVec2(at[i].x + r + 1, at[i].y - r - 12), IM_COL32(0, 0, 0, 255),
                    w.module(int(i)).name.c_str());
    }
    if (clicked) {
      const ImVec2 mouse = ImGui::GetIO().MousePos;
      float best = 144;
      int who = -1;
      for (size_t i = 0; i < n; ++i) {
        const float d = (at[i].x - mouse.x) * (at[i].x - mouse.x) + (at[i].y - mouse.y) * (at[i].y - mouse.y);
        if (d < best) best = d, who = int(i);
      }
      m_selected = who;
    }
    auto dockName = [&](int m, int d) {
      const Module& mod = w.module(m);
      return mod.name + "." +
             (d >= 0 && d < int(mod.type->docks.size()) ? mod.type->docks[size_t(d)].name : "?");
    };
    if (ImGui::CollapsingHeader("Connections", ImGuiTreeNodeFlags_DefaultOpen)) {
      size_t shown = 0;
      for (const Connection& c : w.connections()) {
        if (++shown > 200) {
          ImGui::TextDisabled("... and %zu more", w.connections().size() - 200);
          break;
        }
        ImGui::Text("%s - %s", dockName(c.moduleA, c.dockA).c_str(), dockName(c.moduleB, c.dockB).c_str());
      }
    }
    if (ImGui::CollapsingHeader("Dock events", ImGuiTreeNodeFlags_DefaultOpen)) {
      const std::vector<DockEvent>& ev = w.events();
      if (ev.empty()) ImGui::TextDisabled("(none yet)");
      for (size_t k = ev.size(), shown = 0; k-- > 0 && shown < 50; ++shown) {  // newest first
        const DockEvent& e = ev[k];
        const ImVec4 colour =
            e.kind == DockEventKind::Broken ? kErrorColor : ImGui::GetStyle().Colors[ImGuiCol_Text];
        ImGui::TextColored(colour, "t=%.2f %s %s - %s", e.time, dockEventName(e.kind),
                           dockName(e.moduleA, e.dockA).c_str(), dockName(e.moduleB, e.dockB).c_str());
      }
    }
    ImGui::End();
    (void)width;
    if (!open) m_graph = false;
  }

  /// What the graph panel shows, for the screenshot line (tests): "N connections, M components"
  /// or "hidden".
  std::string graphLine() const {
    if (!m_graph) return "hidden";
    return std::to_string(m_world->connections().size()) + " connections, " +
           std::to_string(m_componentCount) + " component" + (m_componentCount == 1 ? "" : "s");
  }

  std::string moduleName(int index) const {
    return index >= 0 && index < int(m_world->modules().size()) ? m_world->module(index).name : "?";
  }

  void drawInspector(int width, int height) {
    if (m_selected < 0 || m_selected >= int(m_world->modules().size())) return;
    World& w = *m_world;
    const Module& m = w.module(m_selected);
    ImGui::SetNextWindowPos(ImVec2(float(width) - 8, 8), ImGuiCond_Appearing, ImVec2(1, 0));
    // A fixed width (long lines wrap) and a height fitted to the content every frame, up to the
    // window's height; more scrolls.
    ImGui::SetNextWindowSize(ImVec2(kInspectorWidth, 0), ImGuiCond_Always);
    ImGui::SetNextWindowSizeConstraints(ImVec2(kInspectorWidth, 0),
                                        ImVec2(kInspectorWidth, float(height) - 16));
    bool open = true;
    // The ### id keeps one window (position) whatever module it shows.
    const std::string title = m.name + "###inspector";
    ImGui::Begin(title.c_str(), &open, ImGuiWindowFlags_NoSavedSettings);
    ImGui::Text("%s   type %s   id %d", m.name.c_str(), m.type->name.c_str(), m.id);
    if (!m.behaviourFile.empty()) {
      const std::string rel =
          fs::path(m.behaviourFile).lexically_relative(m_session.options().projectRoot).string();
      ImGui::TextDisabled("behaviour %s",
                          rel.empty() || rel.starts_with("..") ? m.behaviourFile.c_str() : rel.c_str());
    }
    if (m.fixed) ImGui::TextDisabled("fixed base");
    if (!m.fault.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, kErrorColor);
      ImGui::TextWrapped("FAULT: %s", m.fault.c_str());
      ImGui::PopStyleColor();
    }
    if (!m.type->joints.empty() && ImGui::CollapsingHeader("Joints", ImGuiTreeNodeFlags_DefaultOpen) &&
        ImGui::BeginTable("joints", 3, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
      ImGui::TableSetupColumn("joint");
      ImGui::TableSetupColumn("angle");
      ImGui::TableSetupColumn("command");
      ImGui::TableHeadersRow();
      for (size_t j = 0; j < m.type->joints.size(); ++j) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(m.type->joints[j].name.c_str());
        ImGui::TableNextColumn();
        ImGui::Text("%+7.1f deg", deg(w.jointAngle(m_selected, int(j))));
        ImGui::TableNextColumn();
        const JointCommand& c = m.commands[j];
        if (c.mode == JointMode::Servo)
          ImGui::Text("servo %+.1f deg", deg(c.value));
        else if (c.mode == JointMode::Velocity)
          ImGui::Text("speed %+.1f deg/s", deg(c.value));
        else
          ImGui::TextDisabled("off");
      }
      ImGui::EndTable();
    }
    if (!m.type->docks.empty() && ImGui::CollapsingHeader("Docks", ImGuiTreeNodeFlags_DefaultOpen) &&
        ImGui::BeginTable("docks", 3, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
      ImGui::TableSetupColumn("dock");
      ImGui::TableSetupColumn("state");
      ImGui::TableSetupColumn("peer");
      ImGui::TableHeadersRow();
      for (size_t d = 0; d < m.type->docks.size(); ++d) {
        const DockState& st = m.docks[d];
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(m.type->docks[d].name.c_str());
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(!st.enabled ? "disabled" : st.engaged ? "engaged" : "enabled");
        ImGui::TableNextColumn();
        if (st.engaged && st.peerModule >= 0) {
          const Module& peer = w.module(st.peerModule);
          const std::string dock = st.peerDock >= 0 && st.peerDock < int(peer.type->docks.size())
                                       ? peer.type->docks[size_t(st.peerDock)].name
                                       : "?";
          ImGui::Text("%s.%s", moduleName(st.peerModule).c_str(), dock.c_str());
        } else {
          ImGui::TextDisabled("-");
        }
      }
      ImGui::EndTable();
    }
    m_plots.sample(w, m_selected);
    if (ImGui::CollapsingHeader("Plots", ImGuiTreeNodeFlags_DefaultOpen)) m_plots.draw();
    const std::string percepts = w.describePercepts(m_selected);
    if (!percepts.empty() && ImGui::CollapsingHeader("Percepts", ImGuiTreeNodeFlags_DefaultOpen))
      ImGui::TextWrapped("%s", percepts.c_str());
    auto lines = [](const char* title, const std::deque<std::string>& items) {
      if (!ImGui::CollapsingHeader(title, ImGuiTreeNodeFlags_DefaultOpen)) return;
      if (items.empty()) {
        ImGui::TextDisabled("(none yet)");
        return;
      }
      // Newest first: the interesting end stays visible without scrolling.
      for (auto it = items.rbegin(); it != items.rend(); ++it) ImGui::TextWrapped("%s", it->c_str());
    };
    lines("Messages received", m.recentMessages);
    lines("Log", m.recentLog);
    ImGui::End();
    if (!open) {
      if (m_follow && m_followModule == m_selected) m_follow = false;
      m_selected = -1;
    }
  }

  const ViewArgs& m_args;
  WorldSession m_session;
  World* m_world = nullptr;  // m_session's current world
  OrbitCamera m_orbit;
  Snapshot m_snapshot;  // what is on screen: clicks pick against it
  Camera m_camera;
  SceneRenderer m_scene;
  bool m_paused = false, m_pausedAtEnd = false, m_quit = false;
  int m_stepRequests = 0;
  double m_speed = 1.0;
  double m_owed = 0;                                   // simulated seconds the clock is ahead of the world
  std::deque<std::pair<double, double>> m_rtfSamples;  // (wall s, sim s) over the last second
  int m_selected = -1;                                 // module index
  LivePlots m_plots;                                   // the selected module's recent joints and series
  bool m_follow = false;
  int m_followModule = -1;
  bool m_graph = true, m_components = false;  // the graph panel; modules coloured by component
  std::vector<int> m_componentOf;             // per module: its component's index (World::components order)
  int m_componentCount = 0;
  std::string m_notice;
  int m_dragButton = -1;
  bool m_dragged = false;
  double m_pressX = 0, m_pressY = 0, m_lastX = 0, m_lastY = 0;
};

int Viewer::run(GLFWwindow* window) {
  glfwSetWindowUserPointer(window, this);
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  std::string err;
  if (!m_scene.init([](const char* name) { return glfwProc(name); }, err)) {
    std::fprintf(stderr, "rm3d view: cannot draw in the window: %s\n", err.c_str());
    return 2;
  }
  // Ours first: ImGui's backend remembers installed callbacks and chains to them.
  glfwSetCharCallback(window, onChar);
  glfwSetKeyCallback(window, onKey);
  glfwSetMouseButtonCallback(window, onButton);
  glfwSetCursorPosCallback(window, onCursor);
  glfwSetScrollCallback(window, onScroll);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini dropped into the working folder
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");

  int exitCode = 0;
  int frame = 0;
  auto last = Clock::now();
  while (!glfwWindowShouldClose(window) && !m_quit) {
    glfwPollEvents();
    const auto now = Clock::now();
    const double wallDt = std::chrono::duration<double>(now - last).count();
    last = now;
    watch();
    advance(wallDt);
    const double rtf = realTimeFactor();

    int fbWidth = 0, fbHeight = 0, winWidth = 0, winHeight = 0;
    glfwGetFramebufferSize(window, &fbWidth, &fbHeight);
    glfwGetWindowSize(window, &winWidth, &winHeight);
    if (fbWidth <= 0 || fbHeight <= 0) {  // minimised
      glfwWaitEventsTimeout(0.1);
      continue;
    }
    buildFrame();
    m_scene.draw(m_snapshot, m_camera, fbWidth, fbHeight);

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    drawStatus(rtf);
    drawErrors(winWidth, winHeight);
    drawInspector(winWidth, winHeight);
    drawGraph(winWidth, winHeight);
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

    if (m_args.frames > 0 && ++frame >= m_args.frames) {
      // The back buffer holds the finished frame until the swap.
      std::vector<uint8_t> rgba;
      m_scene.readPixels(fbWidth, fbHeight, rgba);
      if (!m_args.screenshot.empty()) {
        if (!writePng(m_args.screenshot, fbWidth, fbHeight, rgba, err)) {
          std::fprintf(stderr, "rm3d view: %s\n", err.c_str());
          exitCode = 2;
        } else {
          const PixelStats st = countModulePixels(*m_world, m_snapshot, m_camera, fbWidth, fbHeight, rgba);
          std::printf(
              "screenshot: %d x %d, %d module pixels, %d of them picked as a module, t = %.2f s, selected: "
              "%s, graph: %s\n",
              fbWidth, fbHeight, st.modulePixels, st.picked, m_world->time(),
              m_selected >= 0 ? m_world->module(m_selected).name.c_str() : "none", graphLine().c_str());
        }
      }
      break;
    }
    glfwSwapBuffers(window);
  }

  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  m_scene.release();
  return exitCode;
}

}  // namespace

int viewCommand(const ViewArgs& a, const std::string& root) {
  RunOptions o;
  o.projectRoot = root;
  std::string err;
  if (!parseParams(a.params, o.params, err)) {
    std::fprintf(stderr, "rm3d view: %s\n", err.c_str());
    return 2;
  }
  if (a.seed) o.seed = *a.seed;
  o.threads = a.threads;
  o.chunkSize = a.chunk;
  o.echoLog = !a.quiet;
  o.watchdogSeconds = a.watchdog;
  o.keepHistory = true;  // the inspector shows recent log lines and messages
  if (a.frames > 0 && !a.screenshot.empty() && !prepareOutputFile("--screenshot", a.screenshot, err)) {
    std::fprintf(stderr, "rm3d view: %s\n", err.c_str());
    return 2;
  }
  if (!a.screenshot.empty() && a.frames <= 0) {
    std::fprintf(stderr, "rm3d view: --screenshot needs --exit-after N (the frame to save)\n");
    return 2;
  }

  Viewer viewer(a, o);
  if (!viewer.loadInitial(err)) {
    std::fprintf(stderr, "rm3d view: %s\n", err.c_str());
    return 2;
  }

  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!display || !*display) && (!wayland || !*wayland)) {
    std::fprintf(stderr, "rm3d view: no display available (DISPLAY is not set); %s\n", kNoDisplayHint);
    return 2;
  }
  if (!glfwInit()) {
    std::fprintf(stderr, "rm3d view: no display available (%s); %s\n", glfwLastError().c_str(),
                 kNoDisplayHint);
    return 2;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_FALSE);  // wide lines stay legal
  const std::string title = "RM3D - " + fs::path(a.world).filename().string();
  GLFWwindow* window = glfwCreateWindow(kWindowWidth, kWindowHeight, title.c_str(), nullptr, nullptr);
  if (!window) {
    std::fprintf(stderr, "rm3d view: cannot open an OpenGL 3.3 core window (%s); %s\n",
                 glfwLastError().c_str(), kNoDisplayHint);
    glfwTerminate();
    return 2;
  }
  const int rc = viewer.run(window);
  glfwDestroyWindow(window);
  glfwTerminate();
  return rc;
}

}  // namespace rm3d
