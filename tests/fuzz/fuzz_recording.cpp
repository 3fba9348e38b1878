// Fuzzes the recording reader (io/recording.h): the input is written to a file and loaded
// (every size field must be checked against the file before anything is allocated), and when it
// loads, every frame is decoded. A refusal must say what is wrong and name the file.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "io/recording.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = "/tmp/rm3d_fuzz_recording_" + std::to_string(getpid()) + ".rec";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  if (size) std::fwrite(data, 1, size, f);
  std::fclose(f);
  rm3d::Recording rec;
  std::string err;
  if (!rec.load(path, err)) {
    if (err.rfind(path, 0) != 0) std::abort();  // every message names the file
    return 0;
  }
  rm3d::SceneState state;
  rm3d::FrameEvents events;
  for (int64_t i = 0; i < rec.frameCount() && i < 4096; ++i)
    if (!rec.frame(i, state, &events, err)) break;
  rec.frame(rec.frameCount() - 1, state, nullptr, err);  // backwards: from its key frame
  rec.frame(0, state, nullptr, err);
  return 0;
}
