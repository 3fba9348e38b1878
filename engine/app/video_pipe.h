// A video written by ffmpeg: raw RGBA frames go down a pipe into its stdin. ffmpeg is started
// with posix_spawnp and an argument vector (no shell), in its own process group (so Ctrl-C
// reaches rm3d only, which then ends the video cleanly); its stderr goes to a temporary file so
// a failure can quote its last line.
#pragma once

#include <sys/types.h>

#include <cstdio>
#include <string>

namespace rm3d {

class VideoPipe {
 public:
  VideoPipe() = default;
  VideoPipe(const VideoPipe&) = delete;
  VideoPipe& operator=(const VideoPipe&) = delete;
  ~VideoPipe();

  /// Starts ffmpeg writing `path` (H.264 MP4 unless the extension says otherwise). False and
  /// `err` when it cannot be started.
  bool open(const std::string& path, int width, int height, double fps, std::string& err);
  bool isOpen() const { return m_pid > 0; }
  /// Writes one frame. After a failure (ffmpeg gone: EPIPE) it returns false and writes nothing
  /// more; close() reports why.
  bool write(const void* data, size_t bytes);
  bool failed() const { return !m_writeError.empty(); }
  /// Ends the input and waits for ffmpeg. False and `err` (naming the file, ffmpeg's exit status
  /// and its last stderr line) when a write failed or ffmpeg did not exit with 0.
  bool close(std::string& err);

 private:
  std::string lastErrorLine() const;
  std::string m_path;
  pid_t m_pid = -1;
  int m_fd = -1;          ///< ffmpeg's stdin
  FILE* m_log = nullptr;  ///< ffmpeg's stderr
  std::string m_writeError;
};

}  // namespace rm3d
