// `rm3d replay FILE --view`: the recording in a window: a time slider, play/pause, speed, and
// the orbit camera of `rm3d view`. Nothing is simulated; frames are decoded from the file.
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "app/cmd_replay.h"
#include "app/orbit_camera.h"
#include "render/scene_renderer.h"

namespace rm3d {

namespace {

struct ReplayWindow {
  const Recording& rec;
  SceneLayout layout;
  SceneState start, now;
  OrbitCamera orbit;
  int64_t frame = 0, shown = -1;
  bool playing = true;
  float speed = 1;
  double owed = 0;
  int dragButton = -1;
  double lastX = 0, lastY = 0;
  std::string error;

  static ReplayWindow& of(GLFWwindow* w) { return *static_cast<ReplayWindow*>(glfwGetWindowUserPointer(w)); }
  static void onButton(GLFWwindow* w, int button, int action, int) {
    ReplayWindow& v = of(w);
    if (action == GLFW_PRESS && !ImGui::GetIO().WantCaptureMouse && v.dragButton < 0) {
      v.dragButton = button;
      glfwGetCursorPos(w, &v.lastX, &v.lastY);
    } else if (action == GLFW_RELEASE && button == v.dragButton) {
      v.dragButton = -1;
    }
  }
  static void onCursor(GLFWwindow* w, double x, double y) {
    ReplayWindow& v = of(w);
    if (v.dragButton < 0) return;
    const float dx = float(x - v.lastX), dy = float(y - v.lastY);
    v.lastX = x;
    v.lastY = y;
    int width = 0, height = 0;
    glfwGetWindowSize(w, &width, &height);
    if (v.dragButton == GLFW_MOUSE_BUTTON_LEFT)
      v.orbit.orbit(dx, dy);
    else
      v.orbit.pan(dx, dy, height);
  }
  static void onScroll(GLFWwindow* w, double, double dy) {
    if (!ImGui::GetIO().WantCaptureMouse) of(w).orbit.zoom(float(dy));
  }
  static void onKey(GLFWwindow* w, int key, int, int action, int) {
    if (ImGui::GetIO().WantCaptureKeyboard || action == GLFW_RELEASE) return;
    ReplayWindow& v = of(w);
    if (key == GLFW_KEY_SPACE) v.playing = !v.playing;
    if (key == GLFW_KEY_RIGHT) v.frame = std::min(v.frame + 1, v.rec.frameCount() - 1), v.playing = false;
    if (key == GLFW_KEY_LEFT) v.frame = std::max<int64_t>(v.frame - 1, 0), v.playing = false;
    if (key == GLFW_KEY_ESCAPE || key == GLFW_KEY_Q) glfwSetWindowShouldClose(w, 1);
  }

  void advance(double wallDt) {
    if (!playing) {
      owed = 0;
      return;
    }
    owed += wallDt * speed;
    const int64_t steps = int64_t(owed / layout.dt);
    owed -= double(steps) * layout.dt;
    frame = std::min(frame + steps, rec.frameCount() - 1);
    if (frame == rec.frameCount() - 1) playing = false;
  }

  void decode() {
    if (frame == shown) return;
    if (!rec.frame(frame, now, nullptr, error)) return;
    shown = frame;
  }

  void panel() {
    ImGui::SetNextWindowPos(ImVec2(8, 8));
    ImGui::SetNextWindowBgAlpha(0.7f);
    ImGui::Begin(
        "replay", nullptr,
        ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings);
    ImGui::Text("t = %.3f s   step %lld   %zu modules   %d faults   (recorded; nothing is simulated)",
                now.time, (long long)now.steps, layout.modules.size(), now.faults);
    if (ImGui::Button(playing ? "Pause" : "Play")) {
      if (!playing && frame == rec.frameCount() - 1) frame = 0;
      playing = !playing;
    }
    ImGui::SameLine();
    ImGui::SetNextItemWidth(110);
    ImGui::SliderFloat("speed", &speed, 0.125f, 8.0f, "%.3gx", ImGuiSliderFlags_Logarithmic);
    int f = int(frame);
    ImGui::SetNextItemWidth(520);
    if (ImGui::SliderInt("step", &f, 0, int(rec.frameCount() - 1))) {
      frame = f;
      playing = false;
    }
    ImGui::TextDisabled("Space play/pause   Left/Right one step   drag: orbit/pan   wheel: zoom   Esc quit");
    if (!error.empty()) ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "%s", error.c_str());
    ImGui::End();
  }
};

void* glfwProc(const char* name) {
  return reinterpret_cast<void*>(glfwGetProcAddress(name));
}

}  // namespace

int replayViewer(const Recording& rec, const SceneLayout::CameraDef& camera, int frames,
                 const std::string& screenshot) {
  ReplayWindow v{rec, rec.layout(), {}, {}, {}, 0, -1, true, 1, 0, -1, 0, 0, {}};
  v.layout.camera = camera;
  std::string err;
  if (!rec.frame(0, v.start, nullptr, err)) {
    std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
    return 2;
  }
  v.now = v.start;
  v.orbit = OrbitCamera::from(sceneCamera(v.layout, v.start, v.start));
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if (((!display || !*display) && (!wayland || !*wayland)) || !glfwInit()) {
    std::fprintf(stderr,
                 "rm3d replay: --view: no display available; without one use --png, --video or --frames\n");
    return 2;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  const std::string title = "RM3D replay - " + std::filesystem::path(rec.path()).filename().string();
  GLFWwindow* window = glfwCreateWindow(1280, 720, title.c_str(), nullptr, nullptr);
  if (!window) {
    std::fprintf(stderr, "rm3d replay: --view: cannot open an OpenGL 3.3 core window\n");
    glfwTerminate();
    return 2;
  }
  glfwSetWindowUserPointer(window, &v);
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  SceneRenderer scene;
  if (!scene.init([](const char* name) { return glfwProc(name); }, err)) {
    std::fprintf(stderr, "rm3d replay: cannot draw in the window: %s\n", err.c_str());
    glfwDestroyWindow(window);
    glfwTerminate();
    return 2;
  }
  glfwSetMouseButtonCallback(window, ReplayWindow::onButton);
  glfwSetCursorPosCallback(window, ReplayWindow::onCursor);
  glfwSetScrollCallback(window, ReplayWindow::onScroll);
  glfwSetKeyCallback(window, ReplayWindow::onKey);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
  int code = 0, drawn = 0;
  auto last = std::chrono::steady_clock::now();
  while (!glfwWindowShouldClose(window)) {
    glfwPollEvents();
    const auto t = std::chrono::steady_clock::now();
    v.advance(std::chrono::duration<double>(t - last).count());
    last = t;
    v.decode();
    int fbW = 0, fbH = 0;
    glfwGetFramebufferSize(window, &fbW, &fbH);
    if (fbW <= 0 || fbH <= 0) {
      glfwWaitEventsTimeout(0.1);
      continue;
    }
    Snapshot snap = buildSnapshot(v.layout, v.now);
    snap.overlay.clear();
    const Camera cam = v.orbit.camera();
    scene.draw(snap, cam, fbW, fbH);
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    v.panel();
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (frames > 0 && ++drawn >= frames) {
      std::vector<uint8_t> rgba;
      scene.readPixels(fbW, fbH, rgba);
      if (!screenshot.empty() && !writePng(screenshot, fbW, fbH, rgba, err)) {
        std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
        code = 2;
      }
      break;
    }
    glfwSwapBuffers(window);
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  scene.release();
  glfwDestroyWindow(window);
  glfwTerminate();
  return code;
}

}  // namespace rm3d
