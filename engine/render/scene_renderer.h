// Draws a Snapshot with OpenGL 3.3 into whatever framebuffer is bound: the GL drawing shared by
// OffscreenRenderer (OSMesa, no display) and the viewer window (GLFW). GL entry points come from
// a loader the caller supplies (OSMesaGetProcAddress, glfwGetProcAddress) and live in this object,
// not in a process-wide table, so renderers on different contexts and libGLs stay independent.
// GL types stay in the .cpp (pimpl) so including this header pulls in no GL headers.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/function_ref.h"
#include "io/snapshot.h"

namespace rm3d {

/// Returns the address of an OpenGL function by name ("glClear"), or null.
using GlGetProc = FunctionRef<void*(const char* name)>;

class SceneRenderer {
 public:
  SceneRenderer();
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// With the target context current: loads the GL entry points through getProc, compiles the
  /// shaders and makes the shadow map. Returns false and sets err on failure.
  bool init(GlGetProc getProc, std::string& err);
  bool ready() const;
  /// Draws s seen from cam over the whole width x height framebuffer bound for drawing now
  /// (rendered multisampled, then resolved into it); leaves that framebuffer bound. The context
  /// of init must be current.
  void draw(const Snapshot& s, const Camera& cam, int width, int height);
  /// Reads width x height RGBA pixels of the framebuffer bound for reading, top row first.
  void readPixels(int width, int height, std::vector<uint8_t>& rgba) const;
  /// Deletes the GL objects (the context of init must be current). Without a call they go when
  /// their context is destroyed; the destructor makes no GL call, as the context may be gone.
  void release();

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

/// Writes width x height RGBA pixels (top row first) as a PNG; on failure err names the file.
bool writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgba,
              std::string& err);

}  // namespace rm3d
