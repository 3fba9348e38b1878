// `rm3d replay FILE`: draws a recording again without stepping physics, through the same
// buildSnapshot/sceneCamera as the live run (io/scene_state.h), so the frames match it.
#include "app/cmd_replay.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/app.h"
#include "app/html_replay.h"
#include "app/run_world.h"
#include "app/video_pipe.h"
#include "io/run_capture.h"
#include "render/offscreen_renderer.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

nlohmann::json stateJson(const SceneLayout& lay, const SceneState& st) {
  nlohmann::json mods = nlohmann::json::array();
  for (size_t i = 0; i < lay.modules.size(); ++i) {
    const SceneLayout::ModuleInfo& m = lay.modules[i];
    nlohmann::json links = nlohmann::json::array(), joints = nlohmann::json::object(),
                   docks = nlohmann::json::object();
    for (int l = 0; l < m.links; ++l) {
      const Pose& p = st.links[size_t(m.firstLink + l)];
      links.push_back({{"position", {p.pos.x(), p.pos.y(), p.pos.z()}},
                       {"orientation", {p.rot.w(), p.rot.x(), p.rot.y(), p.rot.z()}}});
    }
    for (size_t j = 0; j < m.joints.size(); ++j) joints[m.joints[j]] = st.joints[size_t(m.firstJoint) + j];
    for (size_t d = 0; d < m.docks.size(); ++d) {
      const uint8_t f = st.docks[size_t(m.firstDock) + d];
      docks[m.docks[d]] = {{"enabled", (f & 1) != 0}, {"engaged", (f & 2) != 0}};
    }
    mods.push_back({{"id", m.id},
                    {"name", m.name},
                    {"type", m.type},
                    {"links", links},
                    {"joints", joints},
                    {"docks", docks},
                    {"faulted", st.faulted[i] != 0}});
  }
  return {{"time", st.time}, {"steps", st.steps}, {"faults", st.faults}, {"modules", mods}};
}

}  // namespace

int replayCommand(const ReplayArgs& a) {
  std::string err;
  if (!checkOutputsApart({{"the recording", a.file}},
                         {{"--png", a.png}, {"--video", a.video}, {"--json", a.json}, {"--html", a.html}},
                         err)) {
    std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
    return 2;
  }
  Recording rec;
  if (!rec.load(a.file, err)) {
    std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
    return 2;
  }
  SceneLayout::CameraDef camera = rec.layout().camera;
  if (!applyCameraArgs({a.eye, a.target, a.fov}, camera, err)) {
    std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
    return 2;
  }
  int width = 1280, height = 720;
  if (!a.size.empty() && (std::sscanf(a.size.c_str(), "%dx%d", &width, &height) != 2 || width < 16 ||
                          height < 16 || width > 8192 || height > 8192)) {
    std::fprintf(stderr, "rm3d replay: --size %s: expected WIDTHxHEIGHT, e.g. 1280x720\n", a.size.c_str());
    return 2;
  }
  if (!a.frames.empty() && !prepareOutputFolder("--frames", a.frames, err)) {
    std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
    return 2;
  }
  for (const auto& [flag, path] : {std::pair{"--png", a.png}, std::pair{"--video", a.video},
                                   std::pair{"--json", a.json}, std::pair{"--html", a.html}}) {
    if (!path.empty() && !prepareOutputFile(flag, path, err)) {
      std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
      return 2;
    }
  }
  SceneLayout layout = rec.layout();
  layout.camera = camera;
  const double end = double(rec.frameCount() - 1) * layout.dt;
  std::printf("%s: %lld frames, %.2f s, %zu modules, recorded from %s\n", a.file.c_str(),
              (long long)rec.frameCount(), end, layout.modules.size(), rec.meta().worldFile.c_str());
  if (!a.html.empty()) {
    HtmlReplayStats stats;
    if (!writeHtmlReplay(rec, camera, a.html, stats, err)) {
      std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
      return 2;
    }
    std::printf("wrote %s (%.1f MiB, %lld of %lld frames%s)\n", a.html.c_str(),
                double(stats.bytes) / (1 << 20), (long long)stats.keptFrames, (long long)stats.recordedFrames,
                stats.stride > 1 ? ", fewer to keep the page small" : "");
  }
  if (a.view) return replayViewer(rec, camera, a.viewFrames, a.screenshot);

  SceneState start, st;
  if (!rec.frame(0, start, nullptr, err)) {
    std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
    return 2;
  }
  const auto picture = [&](const SceneState& now) {
    Snapshot snap = buildSnapshot(layout, now);
    if (a.labels) addModuleLabels(layout, now, snap);
    return snap;
  };
  int code = 0;
  // Video and frames: every n steps from step n, as the live run drew them.
  if (!a.video.empty() || !a.frames.empty()) {
    OffscreenRenderer renderer;
    if (!renderer.init(width, height, err)) {
      std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
      return 2;
    }
    const int n = a.every > 0 ? a.every : std::max(1, int(std::lround(1.0 / (30.0 * layout.dt))));
    VideoPipe video;
    if (!a.video.empty() && !video.open(a.video, width, height, 1.0 / (n * layout.dt), err)) {
      std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
      return 2;
    }
    long long frameNo = 0;
    for (int64_t i = 1; i < rec.frameCount(); ++i) {
      if (!rec.frame(i, st, nullptr, err)) {
        std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
        code = 2;
        break;
      }
      if (st.steps % n != 0) continue;
      renderer.draw(picture(st), sceneCamera(layout, start, st));
      if (video.isOpen() && !video.write(renderer.rgba().data(), renderer.rgba().size())) {
        std::fprintf(stderr, "rm3d replay: --video %s: ffmpeg stopped taking frames\n", a.video.c_str());
        code = 2;
        break;
      }
      if (!a.frames.empty()) {
        char name[64];
        std::snprintf(name, sizeof name, "frame_%06lld.png", frameNo);
        if (!renderer.writePng((fs::path(a.frames) / name).string(), err)) {
          std::fprintf(stderr, "rm3d replay: --frames: %s\n", err.c_str());
          code = 2;
          break;
        }
      }
      ++frameNo;
    }
    if (video.isOpen()) {
      if (!video.close(err)) {
        std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
        code = 2;
      } else {
        std::printf("wrote %lld frames to %s\n", frameNo, a.video.c_str());
      }
    }
  }
  const int64_t pick = a.at ? rec.frameAt(*a.at) : rec.frameCount() - 1;
  if (a.at && *a.at > end + 1e-9) {
    std::fprintf(stderr, "rm3d replay: --at %g: the recording ends at t=%.4g s\n", *a.at, end);
    return 2;
  }
  if ((!a.png.empty() || !a.json.empty()) && !rec.frame(pick, st, nullptr, err)) {
    std::fprintf(stderr, "rm3d replay: %s\n", err.c_str());
    return 2;
  }
  if (!a.png.empty()) {
    OffscreenRenderer renderer;
    if (!renderer.init(width, height, err)) {
      std::fprintf(stderr, "rm3d replay: --png: %s\n", err.c_str());
      return 2;
    }
    renderer.draw(picture(st), sceneCamera(layout, start, st));
    if (!renderer.writePng(a.png, err)) {
      std::fprintf(stderr, "rm3d replay: --png: %s\n", err.c_str());
      code = 2;
    }
  }
  if (!a.json.empty()) {
    std::ofstream f(a.json);
    f << stateJson(layout, st).dump(2) << "\n";
    f.close();
    if (!f) {
      std::fprintf(stderr, "rm3d replay: --json %s: cannot write the file\n", a.json.c_str());
      code = 2;
    }
  }
  return code;
}

}  // namespace rm3d
