// `rm3d run --trace FILE.csv`: a time series of the whole world as one CSV table in long format,
// one row per module per traced step (and one for the world script's series), that pandas, R
// and spreadsheets read as it is. Columns (README, "Traces and plots"):
//
//   time, step, module_id, module, type, x, y, z, qw, qx, qy, qz,
//   joint.<name>.angle, joint.<name>.target, joint.<name>.torque   (per joint name of any type)
//   dock.<name>, dock.<name>.peer                                  (per dock name of any type)
//   trace.<name>                                                   (per series a script records)
//
// A cell is empty where the column does not apply to the row (a joint the module's type lacks, a
// target while the joint is not a servo, a series not recorded since the module's last row).
// Columns are added as they first appear (a module type spawned later, a series first recorded
// at t = 3 s), so rows go to FILE.part while the run lasts and finish() writes FILE: the header,
// then every row padded to the final width.
//
// Per step the writer does no name look-ups and no allocation once warm: each module's columns
// are resolved once (per type, and per series slot when a slot is new), and rows are formatted
// with std::to_chars into a buffer written out in 1 MiB blocks.
#pragma once

#include <cstdint>
#include <cstdio>
#include <deque>
#include <string>
#include <unordered_map>
#include <vector>

namespace rm3d {

class World;
struct ModuleTypeDef;
struct TraceSeries;

class TraceWriter {
 public:
  TraceWriter() = default;
  ~TraceWriter();
  TraceWriter(const TraceWriter&) = delete;
  TraceWriter& operator=(const TraceWriter&) = delete;

  /// Starts a trace of every `every`-th step into `path`. False and err (naming the file) when
  /// the part file cannot be made.
  bool open(const std::string& path, int every, std::string& err);
  bool isOpen() const { return m_part != nullptr; }
  /// Writes the world's rows now if the step is due (step % every == 0, step 0 included). Call
  /// once after loading and after every step. Takes the series recorded since the last rows.
  void sample(World& w);
  /// Writes the last step's rows if they are not written yet (and a world row for series
  /// recorded after them, e.g. in world.on_end), then FILE, and removes FILE.part. False and err
  /// when a write failed.
  bool finish(World& w, std::string& err);
  /// Drops the trace (a run that never loaded): removes FILE.part, writes nothing.
  void discard();
  int64_t rows() const { return m_rows; }
  size_t columns() const { return m_columns.size(); }

 private:
  struct TypeLayout {
    const ModuleTypeDef* type;
    std::vector<int> joints;  ///< first of 3 columns (angle, target, torque) per joint
    std::vector<int> docks;   ///< first of 2 columns (state, peer) per dock
  };
  enum class Cell : uint8_t { Empty, Real, Exact, Integer };

  void writeRows(World& w, bool modules);
  void writeRow(const std::string& who, TraceSeries& series, std::vector<int>& seriesColumns);
  int column(const std::string& name);
  const TypeLayout& layout(const ModuleTypeDef* type);
  void flushBuffer();
  void put(int column, Cell kind, double v) {
    m_kind[size_t(column)] = kind;
    m_value[size_t(column)] = v;
  }

  std::string m_path, m_partPath;
  std::FILE* m_part = nullptr;
  bool m_writeFailed = false;
  int m_every = 1;
  int64_t m_lastStep = -1;  ///< the step of the last rows written
  int64_t m_rows = 0;
  std::vector<std::string> m_columns;
  std::unordered_map<std::string, int> m_columnIndex;  ///< used when something new appears only
  /// (line number where a width starts, the width): rows are padded to the final width.
  std::vector<std::pair<int64_t, int>> m_widths;
  std::deque<TypeLayout> m_layouts;
  std::vector<const TypeLayout*> m_moduleLayout;  ///< per module
  std::vector<std::string> m_moduleText;          ///< per module: "id,name,type" as CSV cells
  std::vector<std::vector<int>> m_moduleSeries;   ///< per module: column per series slot
  std::vector<int> m_worldSeries;                 ///< column per world-script series slot
  std::string m_prefix;                           ///< "time,step," of the rows being written
  std::vector<Cell> m_kind;                       ///< per column, of the row being written
  std::vector<double> m_value;
  std::string m_buffer;
};

/// A CSV cell for a name: quoted when it holds a comma, quote or leading/trailing space; line
/// breaks and other control characters become spaces (every row stays one line).
std::string csvCell(const std::string& text);

}  // namespace rm3d
