// `rm3d run --record FILE`: a run kept for redrawing, replaying and forking.
//
// File format (version 1; all numbers little-endian):
//   header   8 bytes magic "RM3DREC\n", u32 version, u32 0 (reserved)
//   chunks   u32 tag, u32 CRC-32 of the unpacked payload, u64 unpacked size, u64 packed size,
//            then the payload packed with zlib (deflate)
// Chunks, in order: META (JSON: world file, project root, seed, params, dt, arguments, version),
// LAYO (the scene layout: meshes, items, module names, joints, docks, camera, then cloth, which
// files from before cloth lack: io/scene_state.h),
// then one FRAM per step from step 0 (the state before the first step), then SRCS (every Lua
// text the run read: world script, module types, behaviours, required modules) and END_ (frame
// count). A frame is its clock, the new dock events and faults of that step (frame 0: the
// connections made while the world was built, as "engaged" events; recordings from before
// these have none there), and the state
// arrays (poses as doubles, so a replay rebuilds bit-identical snapshots); every 64th frame is
// whole, the others are XORed with the frame before; the state bytes are then regrouped in
// byte planes of 8-byte lanes (the high bytes of an XOR of close doubles are zeros and pack well).
#pragma once

#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "docking/docking.h"
#include "io/scene_state.h"

namespace rm3d {

constexpr uint32_t kRecordingVersion = 1;
constexpr int kKeyFrameInterval = 64;

struct RecordingMeta {
  std::string worldFile;    ///< absolute, as recorded
  std::string projectRoot;  ///< absolute, as recorded
  uint64_t seed = 1;        ///< the world's seed
  bool seedGiven = false;   ///< --seed was on the command line (else world.set{seed=} or 1)
  std::map<std::string, std::string> params;
  double dt = 1.0 / 60;
  std::vector<std::string> arguments;  ///< the command line
  std::string version;
};

/// What happened in one step besides the state: dock events and new faults.
struct FrameEvents {
  std::vector<DockEvent> docks;
  std::vector<std::pair<int, std::string>> faults;  ///< module index, fault text
};

class RecordingWriter {
 public:
  RecordingWriter() = default;
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  /// Creates the file and writes the header, META and LAYO. False and err on failure.
  bool open(const std::string& path, const RecordingMeta& meta, const SceneLayout& layout, std::string& err);
  /// Appends one frame. After a write error, does nothing (finish() reports it).
  void frame(const SceneState& state, const FrameEvents& events);
  /// SRCS and END_, then closes. False and err (naming the file) when any write failed.
  bool finish(const std::vector<std::pair<std::string, std::string>>& sources, std::string& err);
  bool isOpen() const { return m_file != nullptr; }
  int64_t frames() const { return m_frames; }
  /// Bytes written so far.
  uint64_t bytes() const { return m_bytes; }

 private:
  void chunk(uint32_t tag, const std::vector<uint8_t>& raw);

  std::FILE* m_file = nullptr;
  std::string m_path;
  bool m_failed = false;
  int64_t m_frames = 0;
  uint64_t m_bytes = 0;
  std::vector<uint8_t> m_prev, m_cur, m_raw, m_packed;  // reused: no allocation per frame
};

/// A recording read back: everything but the frames is decoded at once; frames on demand.
class Recording {
 public:
  /// Reads and checks the whole file. False and err ("FILE: what is wrong, what was expected").
  bool load(const std::string& path, std::string& err);

  const RecordingMeta& meta() const { return m_meta; }
  const SceneLayout& layout() const { return m_layout; }
  /// Lua texts by absolute path as recorded.
  const std::vector<std::pair<std::string, std::string>>& sources() const { return m_sources; }
  int64_t frameCount() const { return int64_t(m_frames.size()); }
  /// Decodes frame i (0: before the first step) into out; events (if given) too.
  bool frame(int64_t i, SceneState& out, FrameEvents* events, std::string& err) const;
  /// The frame whose time is closest to t (frames are dt apart from t = 0).
  int64_t frameAt(double t) const;
  const std::string& path() const { return m_path; }

 private:
  struct Packed {
    uint32_t crc = 0;
    uint64_t rawSize = 0;
    std::vector<uint8_t> data;
  };
  bool unpack(const Packed& p, std::vector<uint8_t>& raw, std::string& err) const;

  std::string m_path;
  RecordingMeta m_meta;
  SceneLayout m_layout;
  std::vector<std::pair<std::string, std::string>> m_sources;
  std::vector<Packed> m_frames;
  // Decoding cache: the last frame decoded (sequential playback decodes one frame per call).
  mutable int64_t m_cached = -1;
  mutable std::vector<uint8_t> m_cachedState, m_scratch;
};

}  // namespace rm3d
