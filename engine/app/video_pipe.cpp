#include "app/video_pipe.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

extern char** environ;

namespace rm3d {

VideoPipe::~VideoPipe() {
  std::string err;
  if (isOpen()) close(err);
  if (m_log) std::fclose(m_log);
}

bool VideoPipe::open(const std::string& path, int width, int height, double fps, std::string& err) {
  m_path = path;
  m_writeError.clear();
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    err = "--video " + path + ": cannot make a pipe to ffmpeg (" + std::strerror(errno) + ")";
    return false;
  }
  if (!m_log) m_log = std::tmpfile();
  if (m_log) ::fcntl(fileno(m_log), F_SETFD, FD_CLOEXEC);
  char size[32], rate[32];
  std::snprintf(size, sizeof size, "%dx%d", width, height);
  std::snprintf(rate, sizeof rate, "%.3f", fps);
  std::vector<std::string> args = {
      "ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgba", "-s", size, "-r", rate,
      "-i", "-", "-pix_fmt", "yuv420p", "-vcodec", "libx264", "-crf", "23",
      // "file:": a name starting with '-' or holding "proto:" is still just a file name.
      "file:" + path};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  if (m_log) posix_spawn_file_actions_adddup2(&actions, fileno(m_log), STDERR_FILENO);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGPIPE);  // rm3d ignores SIGPIPE; ffmpeg gets the usual behaviour back
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setpgroup(&attr, 0);  // Ctrl-C at the terminal reaches rm3d, which ends the video
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETPGROUP);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, "ffmpeg", &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  ::close(fds[0]);
  if (rc != 0) {
    ::close(fds[1]);
    err = "--video " + path + ": cannot start ffmpeg (" + std::strerror(rc) + ")";
    return false;
  }
  m_pid = pid;
  m_fd = fds[1];
  return true;
}

bool VideoPipe::write(const void* data, size_t bytes) {
  if (m_fd < 0 || failed()) return false;
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::write(m_fd, p, bytes);
    if (n < 0) {
      if (errno == EINTR) continue;
      m_writeError = std::strerror(errno);
      ::close(m_fd);  // ffmpeg is gone (EPIPE) or broken: no more frames
      m_fd = -1;
      return false;
    }
    p += n;
    bytes -= size_t(n);
  }
  return true;
}

std::string VideoPipe::lastErrorLine() const {
  if (!m_log) return {};
  std::fflush(m_log);
  std::string text;
  char buf[4096];
  ::lseek(fileno(m_log), 0, SEEK_SET);
  for (ssize_t n; (n = ::read(fileno(m_log), buf, sizeof buf)) > 0;) text.append(buf, size_t(n));
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.pop_back();
  const size_t nl = text.find_last_of("\r\n");
  std::string last = nl == std::string::npos ? text : text.substr(nl + 1);
  if (last.size() > 300) last = last.substr(0, 300) + "...";
  return last;
}

bool VideoPipe::close(std::string& err) {
  if (m_pid <= 0) return true;
  if (m_fd >= 0) ::close(m_fd);
  m_fd = -1;
  int status = 0;
  pid_t got;
  do {
    got = ::waitpid(m_pid, &status, 0);
  } while (got < 0 && errno == EINTR);
  m_pid = -1;
  std::string why;
  if (got < 0)
    why = std::string("lost track of ffmpeg (") + std::strerror(errno) + ")";
  else if (WIFSIGNALED(status))
    why = "ffmpeg was killed by signal " + std::to_string(WTERMSIG(status));
  else if (WEXITSTATUS(status) != 0)
    why = "ffmpeg exited with status " + std::to_string(WEXITSTATUS(status));
  if (!m_writeError.empty())
    why = (why.empty() ? std::string() : why + "; ") + "writing frames to it failed (" + m_writeError + ")";
  if (why.empty()) return true;
  err = "--video " + m_path + ": " + why;
  const std::string last = lastErrorLine();
  if (!last.empty()) err += ": ffmpeg said: " + last;
  return false;
}

}  // namespace rm3d
