// OSMesa implementation of OffscreenRenderer: an OSMesa context whose default framebuffer is a
// memory buffer, drawn into by the shared SceneRenderer and read back top row first.
//
// libOSMesa is opened when a renderer is first made, not linked: it brings in LLVM (llvmpipe),
// whose loading and relocation cost every process about 55 ms before main on the development
// machine, a headless `rm3d run` (most of a sweep's runs) or `import rm3d` included. Only the
// four OSMesa entry points are looked up here; the GL ones come through OSMesaGetProcAddress as
// before. Opened RTLD_LOCAL (its gl* symbols stay out of the process's namespace) and never
// closed (a Mesa with LLVM inside is not made to be unloaded).
#include "render/offscreen_renderer.h"

#include <GL/osmesa.h>
#include <dlfcn.h>

#include <string>
#include <type_traits>

#include "render/scene_renderer.h"

namespace rm3d {

namespace {

/// The OSMesa entry points the renderer calls, from the library opened at run time.
struct OsMesa {
  decltype(&::OSMesaCreateContextAttribs) createContextAttribs = nullptr;
  decltype(&::OSMesaMakeCurrent) makeCurrent = nullptr;
  decltype(&::OSMesaDestroyContext) destroyContext = nullptr;
  decltype(&::OSMesaGetProcAddress) getProcAddress = nullptr;

  /// Opens the library (Debian's soname first) and looks the entry points up; false and why.
  bool open(std::string& err) {
    void* lib = nullptr;
    std::string why;
    for (const char* name : {"libOSMesa.so.8", "libOSMesa.so"}) {
      lib = dlopen(name, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
      if (lib) break;
      const char* e = dlerror();
      if (why.empty() && e) why = e;
    }
    if (!lib) {
      err = "offscreen renderer: cannot load libOSMesa.so.8 (" + why +
            "); it comes with Debian's libosmesa6 package";
      return false;
    }
    bool found = true;
    auto fetch = [&](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(lib, name));
      if (!fn && found) {
        found = false;
        err = std::string("offscreen renderer: libOSMesa has no ") + name;
      }
    };
    fetch(createContextAttribs, "OSMesaCreateContextAttribs");
    fetch(makeCurrent, "OSMesaMakeCurrent");
    fetch(destroyContext, "OSMesaDestroyContext");
    fetch(getProcAddress, "OSMesaGetProcAddress");
    return found;
  }
};

}  // namespace

struct OffscreenRenderer::Impl {
  OsMesa os;
  OSMesaContext ctx = nullptr;
  int width = 0, height = 0;
  std::vector<uint8_t> osBuffer;  // OSMesa's default framebuffer (bottom row first)
  std::vector<uint8_t> rgba;
  SceneRenderer scene;

  ~Impl() {
    if (!ctx) return;
    if (scene.ready() && makeCurrent()) scene.release();
    os.makeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
    os.destroyContext(ctx);
  }

  // Contexts are per thread-current, and several renderers may take turns.
  bool makeCurrent() { return os.makeCurrent(ctx, osBuffer.data(), GL_UNSIGNED_BYTE, width, height); }
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
  if (!r.os.open(err)) return false;
  // clang-format off
  const int core[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 0,
                      OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                      OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
  const int compat[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24,
                        OSMESA_PROFILE, OSMESA_COMPAT_PROFILE, 0};
  // clang-format on
  r.ctx = r.os.createContextAttribs(core, nullptr);
  if (!r.ctx) r.ctx = r.os.createContextAttribs(compat, nullptr);
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
  auto proc = [&r](const char* name) { return reinterpret_cast<void*>(r.os.getProcAddress(name)); };
  if (!r.scene.init(proc, err)) {
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
