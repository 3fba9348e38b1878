// Headless renderer: draws a Snapshot with OpenGL through OSMesa (no display, no GPU needed)
// into an RGBA buffer and writes it as a PNG. Used for screenshots, videos and tests.
// GL and OSMesa types stay in the .cpp (pimpl) so including this header pulls in no GL headers.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/snapshot.h"

namespace rm3d {

class OffscreenRenderer {
 public:
  OffscreenRenderer();
  ~OffscreenRenderer();
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  /// Creates the OSMesa context (OpenGL 3.3 core profile, falling back to a compatibility
  /// context if core is refused), shaders and buffers. Returns false and sets err on failure.
  bool init(int width, int height, std::string& err);
  /// Renders s seen from cam into the internal RGBA buffer. Does nothing before a successful init.
  void draw(const Snapshot& s, const Camera& cam);
  /// width * height * 4 bytes, sRGB, top row first.
  const std::vector<uint8_t>& rgba() const;
  /// Writes the last drawn frame; on failure err names the file and the reason.
  bool writePng(const std::string& path, std::string& err) const;
  int width() const;
  int height() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace rm3d
