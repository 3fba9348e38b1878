// OSMesa implementation of OffscreenRenderer: an OSMesa context whose default framebuffer is a
// memory buffer, drawn into by the shared SceneRenderer and read back top row first.
#include "render/offscreen_renderer.h"

#include <GL/osmesa.h>

#include "render/scene_renderer.h"

namespace rm3d {

namespace {

void* osmesaProc(const char* name) {
  return reinterpret_cast<void*>(OSMesaGetProcAddress(name));
}

}  // namespace

struct OffscreenRenderer::Impl {
  OSMesaContext ctx = nullptr;
  int width = 0, height = 0;
  std::vector<uint8_t> osBuffer;  // OSMesa's default framebuffer (bottom row first)
  std::vector<uint8_t> rgba;
  SceneRenderer scene;

  ~Impl() {
    if (!ctx) return;
    if (scene.ready() && makeCurrent()) scene.release();
    OSMesaMakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
    OSMesaDestroyContext(ctx);
  }

  // Contexts are per thread-current, and several renderers may take turns.
  bool makeCurrent() { return OSMesaMakeCurrent(ctx, osBuffer.data(), GL_UNSIGNED_BYTE, width, height); }
};

OffscreenRenderer::OffscreenRenderer() : m_impl(std::make_unique<Impl>()) {}
OffscreenRenderer::~OffscreenRenderer() = default;

bool OffscreenRenderer::init(int width, int height, std::string& err) {
  if (m_impl->ctx) m_impl = std::make_unique<Impl>();  // re-init: drop the old context
  Impl& r = *m_impl;
  if (width <= 0 || height <= 0) {
    err = "offscreen renderer: invalid size " + std::to_string(width) + "x" + std::to_string(height);
    return false;
  }
  // clang-format off
  const int core[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 0,
                      OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                      OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
  const int compat[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24,
                        OSMESA_PROFILE, OSMESA_COMPAT_PROFILE, 0};
  // clang-format on
  r.ctx = OSMesaCreateContextAttribs(core, nullptr);
  if (!r.ctx) r.ctx = OSMesaCreateContextAttribs(compat, nullptr);
  if (!r.ctx) {
    err = "offscreen renderer: OSMesa refused both core 3.3 and compatibility contexts";
    return false;
  }
  r.width = width;
  r.height = height;
  r.osBuffer.assign(size_t(width) * height * 4, 0);
  r.rgba.assign(size_t(width) * height * 4, 0);
  if (!r.makeCurrent()) {
    err = "offscreen renderer: OSMesaMakeCurrent failed";
    return false;
  }
  if (!r.scene.init(osmesaProc, err)) {
    err = "offscreen renderer: " + err;
    return false;
  }
  return true;
}

void OffscreenRenderer::draw(const Snapshot& s, const Camera& cam) {
  Impl& r = *m_impl;
  if (!r.ctx || !r.scene.ready() || !r.makeCurrent()) return;
  r.scene.draw(s, cam, r.width, r.height);  // into OSMesa's framebuffer (0), bound since makeCurrent
  r.scene.readPixels(r.width, r.height, r.rgba);
}

const std::vector<uint8_t>& OffscreenRenderer::rgba() const {
  return m_impl->rgba;
}
int OffscreenRenderer::width() const {
  return m_impl->width;
}
int OffscreenRenderer::height() const {
  return m_impl->height;
}

bool OffscreenRenderer::writePng(const std::string& path, std::string& err) const {
  const Impl& r = *m_impl;
  if (r.rgba.empty()) {
    err = "cannot write '" + path + "': renderer not initialised";
    return false;
  }
  return rm3d::writePng(path, r.width, r.height, r.rgba, err);
}

}  // namespace rm3d
