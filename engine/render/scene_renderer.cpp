// OpenGL 3.3 implementation of SceneRenderer: faceted Lambert shading with a sun shadow map, a
// procedural grid ground, ray-cast sphere impostors for particle sets, GL_LINES and an
// stb_easy_font text overlay, drawn multisampled and resolved into the caller's framebuffer.
// Also the PNG writer (stb_image_write).
#include "render/scene_renderer.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

// Declare the GL prototypes only so decltype can name their types; every call goes through
// pointers from the caller's loader, because a libGL loaded elsewhere in the process (GLX, GLFW,
// OSMesa) would otherwise capture the gl* symbols and dispatch to a context that is not ours.
// clang-format off
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
// clang-format on

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
// Static so another translation unit (or libstb) may also carry the implementation without clashes.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_easy_font.h>
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

#include "render/view_math.h"

namespace rm3d {
namespace {

// clang-format off
#define RM3D_GL_FUNCS(X)                                                                           \
  X(Clear) X(Viewport) X(Enable) X(Disable) X(DepthMask) X(BlendFunc) X(PolygonOffset)             \
  X(LineWidth) X(DrawArrays) X(ReadPixels) X(PixelStorei) X(CreateShader) X(ShaderSource)          \
  X(CompileShader) X(GetShaderiv) X(GetShaderInfoLog) X(DeleteShader) X(CreateProgram)             \
  X(AttachShader) X(LinkProgram) X(GetProgramiv) X(GetProgramInfoLog) X(DeleteProgram)             \
  X(UseProgram) X(GetUniformLocation) X(Uniform1i) X(Uniform1f) X(Uniform2f) X(Uniform3f)          \
  X(Uniform4f) X(UniformMatrix3fv) X(UniformMatrix4fv) X(GenVertexArrays) X(BindVertexArray)       \
  X(DeleteVertexArrays) X(GenBuffers) X(BindBuffer) X(BufferData) X(DeleteBuffers)                 \
  X(VertexAttribPointer) X(EnableVertexAttribArray) X(GenTextures) X(BindTexture) X(TexImage2D)    \
  X(TexParameteri) X(TexParameterfv) X(ActiveTexture) X(DeleteTextures) X(GenFramebuffers)         \
  X(BindFramebuffer) X(FramebufferTexture2D) X(CheckFramebufferStatus) X(DeleteFramebuffers)       \
  X(DrawBuffer) X(ReadBuffer) X(GenRenderbuffers) X(BindRenderbuffer) X(RenderbufferStorage)       \
  X(RenderbufferStorageMultisample) X(FramebufferRenderbuffer) X(DeleteRenderbuffers)              \
  X(BlitFramebuffer) X(GetIntegerv) X(BufferSubData)
// clang-format on

/// Per-renderer GL entry points (no process-wide table: renderers stay independent).
struct Gl {
#define RM3D_GL_MEMBER(name) decltype(&::gl##name) name = nullptr;
  RM3D_GL_FUNCS(RM3D_GL_MEMBER)
#undef RM3D_GL_MEMBER
};

constexpr int kShadowSize = 2048;
constexpr int kSamples = 4;
constexpr float kGroundHalf = 50.0f;  // reaches the far plane from any sensible camera
// Towards the sun: from behind-left of the default camera, so its three visible box faces
// (top, -y, +x) all get different brightness.
const Eigen::Vector3f kSunDir = Eigen::Vector3f(0.25f, -0.5f, 0.83f).normalized();
// sRGB, top and horizon of the sky gradient; the ground fades into the horizon colour.
constexpr float kSkyTop[3] = {0.55f, 0.66f, 0.80f}, kSkyHorizon[3] = {0.86f, 0.89f, 0.93f};

const char* kMeshVs = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
uniform mat4 uModel, uViewProj;
uniform mat3 uNormalMat;
out vec3 vWorld, vNormal, vLocal;
void main() {
  vec4 w = uModel * vec4(aPos, 1.0);
  vWorld = w.xyz; vNormal = uNormalMat * aNormal; vLocal = aPos;
  gl_Position = uViewProj * w;
})";

const char* kMeshFs = R"(#version 330 core
in vec3 vWorld, vNormal, vLocal;
uniform vec4 uColor;
uniform vec2 uCell;
uniform vec3 uSunDir, uEye, uFog;
uniform mat4 uLightViewProj;
uniform sampler2DShadow uShadow;
uniform float uTexel, uNormalOffset;
uniform int uGround;
out vec4 fragColor;
float shadow(vec3 n) {
  vec4 l = uLightViewProj * vec4(vWorld + n * uNormalOffset, 1.0);
  vec3 p = l.xyz / l.w * 0.5 + 0.5;
  if (p.z >= 1.0) return 1.0;
  float s = 0.0;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y) s += texture(uShadow, vec3(p.xy + vec2(x, y) * uTexel, p.z));
  return s / 9.0;
}
// Coverage of grid lines `spacing` apart, about `px` pixels wide, faded out where cells
// shrink below a few pixels so the far ground does not turn into moire.
float grid(vec2 p, vec2 spacing, float px) {
  vec2 c = p / spacing, w = max(fwidth(c), vec2(1e-6));
  vec2 d = abs(fract(c - 0.5) - 0.5) / w;
  float line = 1.0 - clamp(min(d.x, d.y) - 0.5 * px + 0.5, 0.0, 1.0);
  return line * clamp(1.5 - 5.0 * max(w.x, w.y), 0.0, 1.0);
}
void main() {
  vec3 n = normalize(vNormal);
  if (dot(n, uEye - vWorld) < 0.0) n = -n;  // any winding, mirrored transforms, open meshes
  vec3 base = uColor.rgb;
  if (uGround == 1) {
    base *= 1.0 - 0.25 * grid(vWorld.xy, vec2(0.1), 1.0);
    base *= 1.0 - 0.5 * grid(vWorld.xy, vec2(1.0), 1.6);
  }
  if (uCell.x > 0.0) base *= 1.0 - 0.35 * grid(vLocal.xy, uCell, 1.0);  // a mesh's own grid (terrain)
  float ndl = max(dot(n, uSunDir), 0.0);
  float lit = 0.30 + 0.08 * n.z + 0.62 * ndl * (ndl > 0.0 ? shadow(n) : 1.0);
  vec3 c = pow(base * lit, vec3(1.0 / 2.2));
  if (uGround == 1) c = mix(c, uFog, smoothstep(15.0, 45.0, length(vWorld.xy - uEye.xy)));
  fragColor = vec4(c, uColor.a);
})";

// Sphere impostors, one point per centre, in eye space: the point is a square covering the
// sphere's outline on screen (which an off-axis sphere stretches outwards), cut to the view and
// centred on what is left, so a sphere whose centre has left the view still shows its part in
// it (a GL drops a point whose centre is outside). Per fragment the eye ray is intersected with
// the sphere for the exact outline, normal and depth. Points are sized in pixels (uFocal: the
// focal length in pixels) and capped by the GL (255 px on llvmpipe), which only a sphere
// filling half the view reaches. The sun's shadow is looked up once per sphere, at its sunward
// point: per fragment it would double the cost on a software GL, and particles are a few
// pixels across.
const char* kSphereVs = R"(#version 330 core
layout(location = 0) in vec3 aCenter;
uniform mat4 uView, uProj, uLightViewProj;
uniform vec3 uSunDir;
uniform vec2 uViewport;
uniform float uRadius, uFocal, uNormalOffset;
uniform sampler2DShadow uShadow;
flat out vec3 vCenter;
flat out float vLit;
void main() {
  vec3 c = (uView * vec4(aCenter, 1.0)).xyz;
  vCenter = c;
  vLit = 1.0;
  gl_Position = vec4(2.0, 2.0, 2.0, 1.0);  // outside the view: dropped, unless placed below
  gl_PointSize = 1.0;
  if (-c.z <= uRadius * 1.0001) return;  // reaching behind the eye: nothing sensible to draw
  // Outward reach of the outline from the projected centre, in pixels: f (tan(t + a) - tan t),
  // with t the centre's angle off the view axis and a the half-angle of the tangent cone.
  float d = length(c), cosT = -c.z / d, sinT = sqrt(max(1.0 - cosT * cosT, 0.0));
  float sinA = uRadius / d, cosA = sqrt(1.0 - sinA * sinA);
  float cosTA = max(cosT * cosA - sinT * sinA, 1e-3);
  float reach = uFocal * sinA / (cosT * cosTA) + 0.25;
  vec4 p = uProj * vec4(c, 1.0);
  vec2 centre = (p.xy / p.w * 0.5 + 0.5) * uViewport;
  vec2 lo = max(centre - reach, vec2(0.0)), hi = min(centre + reach, uViewport);
  if (any(greaterThanEqual(lo, hi))) return;
  gl_PointSize = max(hi.x - lo.x, hi.y - lo.y);
  // At the depth of the sphere's nearest point, so that the depth it writes is never nearer
  // (depth_greater): where the GL honours that it may reject hidden spheres before shading.
  float zFront = c.z + uRadius;
  gl_Position = vec4((lo + hi) / uViewport - 1.0, (uProj[2][2] * zFront + uProj[3][2]) / -zFront, 1.0);
  vec4 l = uLightViewProj * vec4(aCenter + uSunDir * (uRadius + uNormalOffset), 1.0);
  vec3 s = l.xyz / l.w * 0.5 + 0.5;
  if (s.z < 1.0) vLit = texture(uShadow, s);
})";

const char* kSphereFs = R"(#version 330 core
#ifdef GL_ARB_conservative_depth
#extension GL_ARB_conservative_depth : enable
layout(depth_greater) out float gl_FragDepth;
#endif
flat in vec3 vCenter;
flat in float vLit;
uniform mat4 uProj;
uniform vec2 uViewport;
uniform vec3 uSunView, uUpView;
uniform vec4 uColor;  // rgb in sRGB (linear ^ 1 / 2.2), alpha as given
uniform float uRadius;
out vec4 fragColor;
void main() {
  vec2 ndc = gl_FragCoord.xy / uViewport * 2.0 - 1.0;
  vec3 dir = normalize(vec3(ndc.x / uProj[0][0], ndc.y / uProj[1][1], -1.0));
  float b = dot(vCenter, dir);
  vec3 q = b * dir - vCenter;  // centre to the ray's closest point: stable however far the eye is
  float h = uRadius * uRadius - dot(q, q);
  if (h < 0.0) discard;
  vec3 hit = (b - sqrt(h)) * dir;
  vec3 n = (hit - vCenter) / uRadius;
  float zNdc = (uProj[2][2] * hit.z + uProj[3][2]) / -hit.z;
  gl_FragDepth = 0.5 * (gl_DepthRange.diff * zNdc + gl_DepthRange.near + gl_DepthRange.far);
  float ndl = max(dot(n, uSunView), 0.0);
  // Gamma of (colour x light) as the meshes have it, with one pow: uColor is already raised.
  float lit = 0.30 + 0.08 * dot(n, uUpView) + 0.62 * ndl * vLit;
  fragColor = vec4(uColor.rgb * pow(lit, 1.0 / 2.2), uColor.a);
})";

const char* kShadowVs = R"(#version 330 core
layout(location = 0) in vec3 aPos;
uniform mat4 uModel, uLightViewProj;
void main() { gl_Position = uLightViewProj * uModel * vec4(aPos, 1.0); })";

const char* kShadowFs = R"(#version 330 core
void main() {})";

const char* kLineVs = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec4 aColor;
uniform mat4 uViewProj;
out vec4 vColor;
void main() { vColor = aColor; gl_Position = uViewProj * vec4(aPos, 1.0); })";

const char* kLineFs = R"(#version 330 core
in vec4 vColor;
out vec4 fragColor;
void main() { fragColor = vec4(pow(vColor.rgb, vec3(1.0 / 2.2)), vColor.a); })";

// Text in pixel coordinates, origin top-left.
const char* kTextVs = R"(#version 330 core
layout(location = 0) in vec2 aPos;
uniform vec2 uScreen, uOffset;
void main() {
  vec2 p = (aPos + uOffset) / uScreen;
  gl_Position = vec4(p.x * 2.0 - 1.0, 1.0 - p.y * 2.0, 0.0, 1.0);
})";

const char* kTextFs = R"(#version 330 core
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; })";

// Full-screen triangle from gl_VertexID, so the sky needs no vertex buffer.
const char* kSkyVs = R"(#version 330 core
out float vY;
void main() {
  vec2 p = vec2((gl_VertexID & 1) * 4.0 - 1.0, (gl_VertexID >> 1) * 4.0 - 1.0);
  vY = p.y * 0.5 + 0.5;
  gl_Position = vec4(p, 0.0, 1.0);
})";

const char* kSkyFs = R"(#version 330 core
in float vY;
uniform vec3 uTop, uHorizon;
out vec4 fragColor;
void main() { fragColor = vec4(mix(uHorizon, uTop, clamp(vY, 0.0, 1.0)), 1.0); })";

Eigen::Matrix4f ortho(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  for (int i = 0; i < 3; ++i) {
    m(i, i) = 2.0f / (hi[i] - lo[i]);
    m(i, 3) = -(hi[i] + lo[i]) / (hi[i] - lo[i]);
  }
  return m;
}

/// Sun view-projection whose ortho box tightly holds the casters in `box` across the light
/// direction, and reaches kFarPlane beyond them along it so the ground they shade lies inside.
Eigen::Matrix4f fitSunFrustum(const Eigen::AlignedBox3f& box, float& texelWorld) {
  const Eigen::Vector3f centre = box.center();
  const float radius = 0.5f * box.diagonal().norm() + 1.0f;
  const Eigen::Matrix4f lightView = lookAt(centre + kSunDir * radius, centre, {0, 0, 1});
  Eigen::AlignedBox3f ls;
  for (int i = 0; i < 8; ++i)
    ls.extend((lightView * box.corner(Eigen::AlignedBox3f::CornerType(i)).homogeneous()).head<3>());
  const float margin = 0.05f;
  const Eigen::Vector3f lo = ls.min() - Eigen::Vector3f(margin, margin, kFarPlane);
  const Eigen::Vector3f hi = ls.max() + Eigen::Vector3f::Constant(margin);
  Eigen::Matrix4f proj = ortho(lo, hi);
  proj.row(2) *= -1.0f;  // the light looks down -z: the largest view z is nearest (depth 0)
  texelWorld = std::max(hi.x() - lo.x(), hi.y() - lo.y()) / kShadowSize;
  return proj * lightView;
}

}  // namespace

struct SceneRenderer::Impl {
  Gl gl;
  bool loaded = false;  // every entry point and object was made
  GLuint meshProg = 0, shadowProg = 0, lineProg = 0, textProg = 0, skyProg = 0, sphereProg = 0;
  GLuint meshVao = 0, meshVbo = 0, lineVao = 0, lineVbo = 0, textVao = 0, textVbo = 0;
  // Every sphere set's centres, one set after another; grown (glBufferData) only when a frame
  // holds more than ever before, else rewritten in place (glBufferSubData).
  GLuint sphereVao = 0, sphereVbo = 0;
  size_t sphereCapacity = 0;  // centres the buffer holds
  struct {
    GLint view, proj, lightViewProj, viewport, focal, sunDir, sunView, upView, normalOffset, shadow, radius,
        color;
  } sphereLoc{};
  GLuint shadowFbo = 0, shadowTex = 0;
  // Scene targets at the last drawn size: multisampled (if the GL allows), and a single-sampled
  // copy it resolves into. Resolving straight into the caller's framebuffer would need identical
  // formats, which a window's (RGB8, BGRA, ...) often is not; a plain blit converts.
  int targetWidth = 0, targetHeight = 0;
  GLuint msaaFbo = 0, msaaColor = 0, msaaDepth = 0;
  GLuint resolveFbo = 0, resolveColor = 0, resolveDepth = 0;

  GLuint compile(GLenum type, const char* src, std::string& err) {
    GLuint sh = gl.CreateShader(type);
    gl.ShaderSource(sh, 1, &src, nullptr);
    gl.CompileShader(sh);
    GLint ok = 0;
    gl.GetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      char log[2048] = {};
      gl.GetShaderInfoLog(sh, sizeof log, nullptr, log);
      err = std::string("shader compile failed: ") + log;
    }
    return sh;
  }

  GLuint program(const char* vs, const char* fs, std::string& err) {
    GLuint v = compile(GL_VERTEX_SHADER, vs, err), f = compile(GL_FRAGMENT_SHADER, fs, err);
    GLuint p = gl.CreateProgram();
    gl.AttachShader(p, v);
    gl.AttachShader(p, f);
    gl.LinkProgram(p);
    gl.DeleteShader(v);
    gl.DeleteShader(f);
    GLint ok = 0;
    gl.GetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok && err.empty()) {
      char log[2048] = {};
      gl.GetProgramInfoLog(p, sizeof log, nullptr, log);
      err = std::string("shader link failed: ") + log;
    }
    return p;
  }

  GLint loc(GLuint prog, const char* name) { return gl.GetUniformLocation(prog, name); }
  void setMat4(GLuint prog, const char* name, const Eigen::Matrix4f& m) {
    gl.UniformMatrix4fv(loc(prog, name), 1, GL_FALSE, m.data());
  }

  /// Binds a VAO/VBO pair and uploads data; attribs are {location, component count}.
  void upload(GLuint vao, GLuint vbo, const std::vector<float>& data,
              std::initializer_list<std::pair<int, int>> attribs) {
    gl.BindVertexArray(vao);
    gl.BindBuffer(GL_ARRAY_BUFFER, vbo);
    gl.BufferData(GL_ARRAY_BUFFER, data.size() * sizeof(float), data.data(), GL_STREAM_DRAW);
    int stride = 0, offset = 0;
    for (auto [location, count] : attribs) stride += count;
    for (auto [location, count] : attribs) {
      gl.EnableVertexAttribArray(location);
      gl.VertexAttribPointer(location, count, GL_FLOAT, GL_FALSE, stride * sizeof(float),
                             reinterpret_cast<const void*>(offset * sizeof(float)));
      offset += count;
    }
  }

  /// A framebuffer with colour and depth renderbuffers (samples 0: single-sampled); 0 if the GL
  /// refuses it.
  GLuint makeTarget(int samples, int width, int height, GLuint& color, GLuint& depth) {
    GLuint fbo = 0, rbos[2] = {0, 0};
    gl.GenFramebuffers(1, &fbo);
    gl.GenRenderbuffers(2, rbos);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    const GLenum formats[2] = {GL_RGBA8, GL_DEPTH_COMPONENT24};
    const GLenum attachments[2] = {GL_COLOR_ATTACHMENT0, GL_DEPTH_ATTACHMENT};
    for (int i = 0; i < 2; ++i) {
      gl.BindRenderbuffer(GL_RENDERBUFFER, rbos[i]);
      if (samples > 0)
        gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, formats[i], width, height);
      else
        gl.RenderbufferStorage(GL_RENDERBUFFER, formats[i], width, height);
      gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, attachments[i], GL_RENDERBUFFER, rbos[i]);
    }
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      gl.DeleteFramebuffers(1, &fbo);
      gl.DeleteRenderbuffers(2, rbos);
      color = depth = 0;
      return 0;
    }
    color = rbos[0], depth = rbos[1];
    return fbo;
  }

  void dropTargets() {
    GLuint fbos[] = {msaaFbo, resolveFbo}, rbos[] = {msaaColor, msaaDepth, resolveColor, resolveDepth};
    gl.DeleteFramebuffers(2, fbos);  // zeros are ignored
    gl.DeleteRenderbuffers(4, rbos);
    msaaFbo = msaaColor = msaaDepth = resolveFbo = resolveColor = resolveDepth = 0;
    targetWidth = targetHeight = 0;
  }

  /// (Re)makes the scene targets when the size changes (a resized window).
  void ensureTargets(int width, int height) {
    if (width == targetWidth && height == targetHeight) return;
    dropTargets();
    msaaFbo = makeTarget(kSamples, width, height, msaaColor, msaaDepth);
    resolveFbo = makeTarget(0, width, height, resolveColor, resolveDepth);
    targetWidth = width, targetHeight = height;
  }

  struct Text {
    float x, y;  ///< top-left pixel of the text's first glyph
    std::string text;
  };
  void drawText(const std::vector<Text>& texts, int width, int height);
  void uploadSpheres(const std::vector<RenderSpheres>& sets);
  void drawSpheres(const std::vector<RenderSpheres>& sets, bool translucent);
};

namespace {

static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "centres are uploaded as packed xyz");

bool drawable(const RenderSpheres& set) {
  return !set.centers.empty() && std::isfinite(set.radius) && set.radius > 0.0f;
}

}  // namespace

void SceneRenderer::Impl::uploadSpheres(const std::vector<RenderSpheres>& sets) {
  size_t total = 0;
  for (const RenderSpheres& set : sets)
    if (drawable(set)) total += set.centers.size();
  if (total == 0) return;
  gl.BindBuffer(GL_ARRAY_BUFFER, sphereVbo);
  if (total > sphereCapacity) {
    gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(total * sizeof(Eigen::Vector3f)), nullptr, GL_STREAM_DRAW);
    sphereCapacity = total;
  }
  size_t offset = 0;
  for (const RenderSpheres& set : sets) {
    if (!drawable(set)) continue;
    const size_t bytes = set.centers.size() * sizeof(Eigen::Vector3f);
    gl.BufferSubData(GL_ARRAY_BUFFER, GLintptr(offset), GLsizeiptr(bytes), set.centers.data());
    offset += bytes;
  }
}

/// One draw (GL_POINTS) per set whose opacity matches `translucent`; the sphere program's frame
/// uniforms (matrices, eye, sun, shadow) are set by the caller.
void SceneRenderer::Impl::drawSpheres(const std::vector<RenderSpheres>& sets, bool translucent) {
  bool bound = false;
  size_t offset = 0;  // bytes, in the layout uploadSpheres wrote
  for (const RenderSpheres& set : sets) {
    if (!drawable(set)) continue;
    const size_t bytes = set.centers.size() * sizeof(Eigen::Vector3f);
    if ((set.color[3] < 1.0f) == translucent) {
      if (!bound) {
        gl.UseProgram(sphereProg);
        gl.Enable(GL_PROGRAM_POINT_SIZE);
        // Single-sampled: the outline is per pixel anyway (discard), and a software GL would
        // otherwise test and write the computed depth per sample (15% of the time).
        gl.Disable(GL_MULTISAMPLE);
        gl.BindVertexArray(sphereVao);
        gl.BindBuffer(GL_ARRAY_BUFFER, sphereVbo);
        bound = true;
      }
      gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Eigen::Vector3f),
                             reinterpret_cast<const void*>(offset));
      gl.Uniform1f(sphereLoc.radius, set.radius);
      auto gamma = [](float c) { return std::pow(std::max(c, 0.0f), 1.0f / 2.2f); };
      gl.Uniform4f(sphereLoc.color, gamma(set.color[0]), gamma(set.color[1]), gamma(set.color[2]),
                   set.color[3]);
      gl.DrawArrays(GL_POINTS, 0, GLsizei(set.centers.size()));
    }
    offset += bytes;
  }
  if (bound) {
    gl.Disable(GL_PROGRAM_POINT_SIZE);
    gl.Enable(GL_MULTISAMPLE);
  }
}

SceneRenderer::SceneRenderer() : m_impl(std::make_unique<Impl>()) {}
SceneRenderer::~SceneRenderer() = default;

bool SceneRenderer::ready() const {
  return m_impl->loaded;
}

bool SceneRenderer::init(GlGetProc getProc, std::string& err) {
  if (m_impl->loaded) m_impl = std::make_unique<Impl>();  // re-init: the old objects go with their context
  Impl& r = *m_impl;
  Gl& gl = r.gl;
#define RM3D_GL_LOAD(name)                                            \
  gl.name = reinterpret_cast<decltype(gl.name)>(getProc("gl" #name)); \
  if (!gl.name) {                                                     \
    err = "OpenGL function gl" #name " is missing";                   \
    return false;                                                     \
  }
  RM3D_GL_FUNCS(RM3D_GL_LOAD)
#undef RM3D_GL_LOAD

  err.clear();
  r.meshProg = r.program(kMeshVs, kMeshFs, err);
  r.shadowProg = r.program(kShadowVs, kShadowFs, err);
  r.lineProg = r.program(kLineVs, kLineFs, err);
  r.textProg = r.program(kTextVs, kTextFs, err);
  r.skyProg = r.program(kSkyVs, kSkyFs, err);
  r.sphereProg = r.program(kSphereVs, kSphereFs, err);
  if (!err.empty()) return false;
  GLuint vaos[4], vbos[4];
  gl.GenVertexArrays(4, vaos);
  gl.GenBuffers(4, vbos);
  r.meshVao = vaos[0], r.lineVao = vaos[1], r.textVao = vaos[2], r.sphereVao = vaos[3];
  r.meshVbo = vbos[0], r.lineVbo = vbos[1], r.textVbo = vbos[2], r.sphereVbo = vbos[3];
  const GLuint sp = r.sphereProg;
  r.sphereLoc = {r.loc(sp, "uView"),     r.loc(sp, "uProj"),   r.loc(sp, "uLightViewProj"),
                 r.loc(sp, "uViewport"), r.loc(sp, "uFocal"),  r.loc(sp, "uSunDir"),
                 r.loc(sp, "uSunView"),  r.loc(sp, "uUpView"), r.loc(sp, "uNormalOffset"),
                 r.loc(sp, "uShadow"),   r.loc(sp, "uRadius"), r.loc(sp, "uColor")};
  gl.BindVertexArray(r.sphereVao);
  gl.EnableVertexAttribArray(0);
  gl.BindVertexArray(0);

  // Shadow map: depth texture with hardware comparison; outside it everything is lit.
  GLint previous = 0;
  gl.GetIntegerv(GL_FRAMEBUFFER_BINDING, &previous);
  gl.GenTextures(1, &r.shadowTex);
  gl.BindTexture(GL_TEXTURE_2D, r.shadowTex);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, kShadowSize, kShadowSize, 0, GL_DEPTH_COMPONENT,
                GL_FLOAT, nullptr);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
  const float border[4] = {1, 1, 1, 1};
  gl.TexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  gl.GenFramebuffers(1, &r.shadowFbo);
  gl.BindFramebuffer(GL_FRAMEBUFFER, r.shadowFbo);
  gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, r.shadowTex, 0);
  gl.DrawBuffer(GL_NONE);
  gl.ReadBuffer(GL_NONE);
  const bool complete = gl.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  gl.BindFramebuffer(GL_FRAMEBUFFER, GLuint(previous));
  if (!complete) {
    err = "shadow-map framebuffer incomplete";
    return false;
  }
  r.loaded = true;
  return true;
}

void SceneRenderer::release() {
  Impl& r = *m_impl;
  if (!r.loaded) return;
  Gl& gl = r.gl;
  for (GLuint p : {r.meshProg, r.shadowProg, r.lineProg, r.textProg, r.skyProg, r.sphereProg})
    gl.DeleteProgram(p);
  GLuint vaos[] = {r.meshVao, r.lineVao, r.textVao, r.sphereVao};
  GLuint vbos[] = {r.meshVbo, r.lineVbo, r.textVbo, r.sphereVbo};
  gl.DeleteVertexArrays(4, vaos);
  gl.DeleteBuffers(4, vbos);
  gl.DeleteFramebuffers(1, &r.shadowFbo);
  gl.DeleteTextures(1, &r.shadowTex);
  r.dropTargets();
  m_impl = std::make_unique<Impl>();
}

void SceneRenderer::draw(const Snapshot& s, const Camera& cam, int width, int height) {
  Impl& r = *m_impl;
  if (!r.loaded || width <= 0 || height <= 0) return;
  Gl& gl = r.gl;
  GLint target = 0, readTarget = 0;  // where the caller wants the picture, and its read binding
  gl.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &target);
  gl.GetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &readTarget);
  r.ensureTargets(width, height);

  // Un-index every mesh into per-face vertices (position, face normal) in one buffer, so
  // shading is faceted for any mesh. Meshes may change between frames: upload every draw.
  std::vector<float> verts;
  std::vector<std::pair<int, int>> ranges;  // first vertex, count per mesh
  for (const RenderMesh& m : s.meshes) {
    ranges.emplace_back(int(verts.size() / 6), 0);
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
      if (std::max({m.indices[i], m.indices[i + 1], m.indices[i + 2]}) >= m.vertices.size()) continue;
      const Eigen::Vector3f& a = m.vertices[m.indices[i]];
      const Eigen::Vector3f& b = m.vertices[m.indices[i + 1]];
      const Eigen::Vector3f& c = m.vertices[m.indices[i + 2]];
      const Eigen::Vector3f cross = (b - a).cross(c - a);
      if (cross.squaredNorm() == 0.0f) continue;  // degenerate: no area, no normal
      const Eigen::Vector3f n = cross.normalized();
      for (const Eigen::Vector3f* p : {&a, &b, &c})
        verts.insert(verts.end(), {p->x(), p->y(), p->z(), n.x(), n.y(), n.z()});
      ranges.back().second += 3;
    }
  }
  // The ground quad follows the camera target so it always fills the view to the horizon.
  const int groundFirst = int(verts.size() / 6);
  const float gx = cam.target.x(), gy = cam.target.y(), h = kGroundHalf;
  for (auto [dx, dy] : {std::pair{-h, -h}, {h, -h}, {h, h}, {-h, -h}, {h, h}, {-h, h}})
    verts.insert(verts.end(), {gx + dx, gy + dy, 0.0f, 0.0f, 0.0f, 1.0f});
  r.upload(r.meshVao, r.meshVbo, verts, {{0, 3}, {1, 3}});
  auto validItem = [&](const RenderItem& it) {
    return it.mesh >= 0 && it.mesh < int(ranges.size()) && ranges[it.mesh].second > 0;
  };

  Eigen::AlignedBox3f box;  // world bounds of all shadow casters
  for (const RenderItem& it : s.items) {
    if (!validItem(it)) continue;
    for (const Eigen::Vector3f& v : s.meshes[it.mesh].vertices)
      box.extend((it.transform * v.homogeneous()).head<3>());
  }
  Eigen::Matrix4f lightViewProj = Eigen::Matrix4f::Identity();
  float texelWorld = 0.0f;
  gl.BindFramebuffer(GL_FRAMEBUFFER, r.shadowFbo);
  gl.Viewport(0, 0, kShadowSize, kShadowSize);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthMask(GL_TRUE);
  gl.Clear(GL_DEPTH_BUFFER_BIT);
  if (!box.isEmpty()) {
    lightViewProj = fitSunFrustum(box, texelWorld);
    gl.UseProgram(r.shadowProg);
    r.setMat4(r.shadowProg, "uLightViewProj", lightViewProj);
    gl.Enable(GL_POLYGON_OFFSET_FILL);
    gl.PolygonOffset(2.0f, 4.0f);  // slope-scaled bias against shadow acne
    for (const RenderItem& it : s.items) {
      if (!validItem(it) || it.color[3] < 0.5f) continue;  // faint items cast no shadow
      r.setMat4(r.shadowProg, "uModel", it.transform);
      gl.DrawArrays(GL_TRIANGLES, ranges[it.mesh].first, ranges[it.mesh].second);
    }
    gl.Disable(GL_POLYGON_OFFSET_FILL);
  }

  // Scene pass: multisampled if we can, else single-sampled, else straight into the target.
  const GLuint sceneFbo = r.msaaFbo ? r.msaaFbo : r.resolveFbo ? r.resolveFbo : GLuint(target);
  gl.BindFramebuffer(GL_FRAMEBUFFER, sceneFbo);
  gl.Viewport(0, 0, width, height);
  gl.Disable(GL_DEPTH_TEST);
  gl.UseProgram(r.skyProg);
  gl.Uniform3f(r.loc(r.skyProg, "uTop"), kSkyTop[0], kSkyTop[1], kSkyTop[2]);
  gl.Uniform3f(r.loc(r.skyProg, "uHorizon"), kSkyHorizon[0], kSkyHorizon[1], kSkyHorizon[2]);
  gl.BindVertexArray(r.textVao);
  gl.DrawArrays(GL_TRIANGLES, 0, 3);
  gl.Enable(GL_DEPTH_TEST);
  gl.Clear(GL_DEPTH_BUFFER_BIT);

  const Eigen::Matrix4f viewProj = viewProjection(cam, float(width) / float(height));
  const GLuint mp = r.meshProg;
  gl.UseProgram(mp);
  gl.BindVertexArray(r.meshVao);
  r.setMat4(mp, "uViewProj", viewProj);
  r.setMat4(mp, "uLightViewProj", lightViewProj);
  gl.Uniform3f(r.loc(mp, "uSunDir"), kSunDir.x(), kSunDir.y(), kSunDir.z());
  gl.Uniform3f(r.loc(mp, "uEye"), cam.eye.x(), cam.eye.y(), cam.eye.z());
  gl.Uniform3f(r.loc(mp, "uFog"), kSkyHorizon[0], kSkyHorizon[1], kSkyHorizon[2]);
  gl.Uniform1f(r.loc(mp, "uTexel"), 1.0f / kShadowSize);
  gl.Uniform1f(r.loc(mp, "uNormalOffset"), 1.5f * texelWorld);
  gl.Uniform1i(r.loc(mp, "uShadow"), 0);
  gl.ActiveTexture(GL_TEXTURE0);
  gl.BindTexture(GL_TEXTURE_2D, r.shadowTex);
  auto drawMesh = [&](const Eigen::Matrix4f& model, const std::array<float, 4>& color, int first, int count,
                      int ground, const Eigen::Vector2f& cell = Eigen::Vector2f::Zero()) {
    gl.Uniform2f(r.loc(mp, "uCell"), cell.x(), cell.y());
    r.setMat4(mp, "uModel", model);
    const Eigen::Matrix3f normalMat = model.topLeftCorner<3, 3>().inverse().transpose();
    gl.UniformMatrix3fv(r.loc(mp, "uNormalMat"), 1, GL_FALSE, normalMat.data());
    gl.Uniform4f(r.loc(mp, "uColor"), color[0], color[1], color[2], color[3]);
    gl.Uniform1i(r.loc(mp, "uGround"), ground);
    gl.DrawArrays(GL_TRIANGLES, first, count);
  };
  if (s.ground) drawMesh(Eigen::Matrix4f::Identity(), {0.62f, 0.62f, 0.62f, 1.0f}, groundFirst, 6, 1);

  if (!s.spheres.empty()) {
    r.uploadSpheres(s.spheres);
    const Eigen::Matrix4f view = lookAt(cam.eye, cam.target, cam.up);
    const Eigen::Matrix4f proj =
        perspective(cam.fovyDeg, float(width) / float(height), kNearPlane, kFarPlane);
    const Eigen::Vector3f sunView = view.topLeftCorner<3, 3>() * kSunDir;
    const Eigen::Vector3f upView = view.topLeftCorner<3, 3>() * Eigen::Vector3f::UnitZ();
    const auto& at = r.sphereLoc;
    gl.UseProgram(r.sphereProg);
    gl.UniformMatrix4fv(at.view, 1, GL_FALSE, view.data());
    gl.UniformMatrix4fv(at.proj, 1, GL_FALSE, proj.data());
    gl.UniformMatrix4fv(at.lightViewProj, 1, GL_FALSE, lightViewProj.data());
    gl.Uniform3f(at.sunDir, kSunDir.x(), kSunDir.y(), kSunDir.z());
    gl.Uniform2f(at.viewport, float(width), float(height));
    gl.Uniform1f(at.focal, 0.5f * float(height) * proj(1, 1));
    gl.Uniform3f(at.sunView, sunView.x(), sunView.y(), sunView.z());
    gl.Uniform3f(at.upView, upView.x(), upView.y(), upView.z());
    gl.Uniform1f(at.normalOffset, 1.5f * texelWorld);
    gl.Uniform1i(at.shadow, 0);
  }
  // Opaque items and spheres first, then translucent ones blended without writing depth.
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      gl.Enable(GL_BLEND);
      gl.BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
      gl.DepthMask(GL_FALSE);
    }
    gl.UseProgram(mp);
    gl.BindVertexArray(r.meshVao);
    for (const RenderItem& it : s.items)
      if (validItem(it) && (it.color[3] < 1.0f) == (pass == 1))
        drawMesh(it.transform, it.color, ranges[it.mesh].first, ranges[it.mesh].second, 0,
                 s.meshes[it.mesh].grid);
    r.drawSpheres(s.spheres, pass == 1);
  }
  gl.DepthMask(GL_TRUE);

  if (!s.lines.empty()) {
    std::vector<float> lv;
    for (const RenderLine& l : s.lines)
      for (const Eigen::Vector3f* p : {&l.a, &l.b})
        lv.insert(lv.end(), {p->x(), p->y(), p->z(), l.color[0], l.color[1], l.color[2], l.color[3]});
    r.upload(r.lineVao, r.lineVbo, lv, {{0, 3}, {1, 4}});
    gl.UseProgram(r.lineProg);
    r.setMat4(r.lineProg, "uViewProj", viewProj);
    gl.LineWidth(std::max(1.0f, height / 400.0f));
    gl.DrawArrays(GL_LINES, 0, GLsizei(lv.size() / 7));
  }
  gl.Disable(GL_BLEND);
  // Text: labels at their points' pixels (centred, those behind the eye left out), the overlay
  // lines top-left.
  std::vector<Impl::Text> texts;
  const float textScale = std::max(1.0f, std::round(height / 360.0f));
  for (const RenderLabel& l : s.labels) {
    const Eigen::Vector4f c = viewProj * Eigen::Vector4f(l.at.x(), l.at.y(), l.at.z(), 1.0f);
    if (!(c.w() > kNearPlane)) continue;
    std::string text = l.text;
    const float x = (c.x() / c.w() * 0.5f + 0.5f) * float(width),
                y = (0.5f - c.y() / c.w() * 0.5f) * float(height);
    texts.push_back({x - 0.5f * float(stb_easy_font_width(text.data())) * textScale, y, l.text});
  }
  for (size_t i = 0; i < s.overlay.size(); ++i)
    texts.push_back({6.0f * textScale, (6.0f + 12.0f * float(i)) * textScale, s.overlay[i]});
  r.drawText(texts, width, height);

  if (r.msaaFbo && r.resolveFbo) {
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, r.msaaFbo);
    gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, r.resolveFbo);
    gl.BlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  if (sceneFbo != GLuint(target)) {
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, r.resolveFbo ? r.resolveFbo : r.msaaFbo);
    gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(target));
    gl.BlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(target));
  gl.BindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(readTarget));
}

void SceneRenderer::readPixels(int width, int height, std::vector<uint8_t>& rgba) const {
  const Impl& r = *m_impl;
  rgba.assign(size_t(std::max(width, 0)) * size_t(std::max(height, 0)) * 4, 0);
  if (!r.loaded || rgba.empty()) return;
  std::vector<uint8_t> rows(rgba.size());
  r.gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  r.gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
  // GL rows run bottom-up; PNG and callers want top row first.
  const size_t row = size_t(width) * 4;
  for (int y = 0; y < height; ++y)
    std::memcpy(rgba.data() + y * row, rows.data() + (height - 1 - y) * row, row);
}

void SceneRenderer::Impl::drawText(const std::vector<Text>& texts, int width, int height) {
  if (texts.empty()) return;
  // stb_easy_font glyphs are ~7 px tall; scale them up on large images.
  const float scale = std::max(1.0f, std::round(height / 360.0f));
  std::vector<float> tris;
  for (const Text& t : texts) {
    std::string text = t.text;  // stb wants a mutable char*
    std::vector<char> quads(text.size() * 1200 + 64);
    const int n = stb_easy_font_print(0.0f, 0.0f, text.data(), nullptr, quads.data(), int(quads.size()));
    for (int q = 0; q < n; ++q)
      for (int k : {0, 1, 2, 0, 2, 3}) {  // quads -> two triangles (core profile)
        float v[2];
        std::memcpy(v, quads.data() + (q * 4 + k) * 16, sizeof v);  // x, y, z, rgba8
        tris.insert(tris.end(), {t.x + v[0] * scale, t.y + v[1] * scale});
      }
  }
  upload(textVao, textVbo, tris, {{0, 2}});
  gl.Disable(GL_DEPTH_TEST);
  gl.UseProgram(textProg);
  gl.Uniform2f(loc(textProg, "uScreen"), float(width), float(height));
  // Black outline around white glyphs keeps them readable on sky, ground and objects alike.
  gl.Uniform4f(loc(textProg, "uColor"), 0.0f, 0.0f, 0.0f, 1.0f);
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy) {
      gl.Uniform2f(loc(textProg, "uOffset"), dx * scale, dy * scale);
      gl.DrawArrays(GL_TRIANGLES, 0, GLsizei(tris.size() / 2));
    }
  gl.Uniform4f(loc(textProg, "uColor"), 1.0f, 1.0f, 1.0f, 1.0f);
  gl.Uniform2f(loc(textProg, "uOffset"), 0.0f, 0.0f);
  gl.DrawArrays(GL_TRIANGLES, 0, GLsizei(tris.size() / 2));
  gl.Enable(GL_DEPTH_TEST);
}

bool writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgba,
              std::string& err) {
  if (width <= 0 || height <= 0 || rgba.size() < size_t(width) * size_t(height) * 4) {
    err = "cannot write '" + path + "': no picture";
    return false;
  }
  errno = 0;
  if (!stbi_write_png(path.c_str(), width, height, 4, rgba.data(), width * 4)) {
    err = "cannot write '" + path + "': " + (errno ? std::strerror(errno) : "PNG write failed");
    return false;
  }
  return true;
}

}  // namespace rm3d
