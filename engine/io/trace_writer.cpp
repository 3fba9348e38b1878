// `rm3d run --trace`: rows while the run lasts, the file with its header at the end.
#include "io/trace_writer.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>

#include "world/world.h"

namespace rm3d {

namespace {

constexpr size_t kBlock = 1u << 20;  ///< bytes buffered before a write
/// The columns every row has; the first 5 are written as text, the rest from cells.
const char* const kFixedColumns[] = {"time", "step", "module_id", "module", "type", "x",
                                     "y",    "z",    "qw",        "qx",     "qy",   "qz"};
constexpr int kFirstCell = 5;  ///< x

void appendChars(std::string& out, const char* begin, const char* end) {
  out.append(begin, size_t(end - begin));
}

/// Exact (shortest round-trip) text of a double: time and script series.
void appendExact(std::string& out, double v) {
  char buf[32];
  appendChars(out, buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

/// Nine significant digits: poses, joints (1e-8 of the value; 10 nm at 10 m).
void appendReal(std::string& out, double v) {
  char buf[32];
  appendChars(out, buf, std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 9).ptr);
}

void appendInteger(std::string& out, long long v) {
  char buf[24];
  appendChars(out, buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

}  // namespace

std::string csvCell(const std::string& text) {
  std::string t = text;
  for (char& c : t)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  const bool quote =
      t.find_first_of(",\"") != std::string::npos || (!t.empty() && (t.front() == ' ' || t.back() == ' '));
  if (!quote) return t;
  std::string q = "\"";
  for (char c : t) {
    if (c == '"') q += '"';
    q += c;
  }
  return q + "\"";
}

TraceWriter::~TraceWriter() {
  discard();
}

bool TraceWriter::open(const std::string& path, int every, std::string& err) {
  m_path = path;
  m_partPath = path + ".part";
  m_every = std::max(1, every);
  m_part = std::fopen(m_partPath.c_str(), "wb");
  if (!m_part) {
    err = "--trace " + path + ": cannot write " + m_partPath + " (" + std::strerror(errno) + ")";
    return false;
  }
  for (const char* c : kFixedColumns) column(c);
  m_buffer.reserve(kBlock + 4096);
  return true;
}

int TraceWriter::column(const std::string& name) {
  const auto it = m_columnIndex.find(name);
  if (it != m_columnIndex.end()) return it->second;
  const int c = int(m_columns.size());
  m_columns.push_back(name);
  m_columnIndex.emplace(name, c);
  return c;
}

const TraceWriter::TypeLayout& TraceWriter::layout(const ModuleTypeDef* type) {
  for (const TypeLayout& l : m_layouts)
    if (l.type == type) return l;
  TypeLayout l{type, {}, {}};
  for (const JointDef& j : type->joints) {
    l.joints.push_back(column("joint." + j.name + ".angle"));
    column("joint." + j.name + ".target");
    column("joint." + j.name + ".torque");
  }
  for (const DockDef& d : type->docks) {
    l.docks.push_back(column("dock." + d.name));
    column("dock." + d.name + ".peer");
  }
  m_layouts.push_back(std::move(l));  // a deque: pointers to the others stay valid
  return m_layouts.back();
}

void TraceWriter::sample(World& w) {
  if (!m_part || w.steps() % m_every != 0 || w.steps() == m_lastStep) return;
  writeRows(w, true);
}

void TraceWriter::writeRows(World& w, bool modules) {
  m_lastStep = w.steps();
  m_prefix.clear();
  appendExact(m_prefix, w.time());
  m_prefix += ',';
  appendInteger(m_prefix, w.steps());
  m_prefix += ',';
  const size_t n = w.modules().size();
  if (modules) {
    if (m_moduleText.size() < n) {  // modules spawned since the last rows
      for (size_t i = m_moduleText.size(); i < n; ++i) {
        const Module& m = w.module(int(i));
        m_moduleText.push_back(std::to_string(m.id) + "," + csvCell(m.name) + "," + csvCell(m.type->name));
      }
      m_moduleSeries.resize(n);
      m_moduleLayout.resize(n, nullptr);
    }
    for (size_t i = 0; i < n; ++i) {
      const Module& m = w.module(int(i));
      TraceSeries& traces = w.moduleTraces(int(i));
      if (!m_moduleLayout[i]) m_moduleLayout[i] = &layout(m.type);
      const TypeLayout& l = *m_moduleLayout[i];
      std::vector<int>& series = m_moduleSeries[i];
      for (size_t s = series.size(); s < traces.names.size(); ++s)
        series.push_back(column("trace." + traces.names[s]));
      m_kind.assign(m_columns.size(), Cell::Empty);  // no allocation once the width is reached
      m_value.resize(m_columns.size());
      const Pose p = w.modulePose(int(i));
      const double pose[7] = {p.pos.x(), p.pos.y(), p.pos.z(), p.rot.w(), p.rot.x(), p.rot.y(), p.rot.z()};
      for (int k = 0; k < 7; ++k) put(kFirstCell + k, Cell::Real, pose[k]);
      for (size_t j = 0; j < l.joints.size(); ++j) {
        const int c = l.joints[j];
        put(c, Cell::Real, w.jointAngle(int(i), int(j)));
        if (m.commands[j].mode == JointMode::Servo) put(c + 1, Cell::Real, m.commands[j].value);
        put(c + 2, Cell::Real, w.jointTorque(int(i), int(j)));
      }
      for (size_t d = 0; d < l.docks.size(); ++d) {
        const DockState& s = m.docks[d];
        put(l.docks[d], Cell::Integer, s.engaged ? 2 : s.enabled ? 1 : 0);
        if (s.engaged) put(l.docks[d] + 1, Cell::Integer, w.module(s.peerModule).id);
      }
      writeRow(m_moduleText[i], traces, series);
    }
  }
  // The world's row: only when one of its series was recorded since its last row.
  TraceSeries& ws = w.worldTraces();
  if (std::find(ws.fresh.begin(), ws.fresh.end(), 1) != ws.fresh.end()) {
    for (size_t s = m_worldSeries.size(); s < ws.names.size(); ++s)
      m_worldSeries.push_back(column("trace." + ws.names[s]));
    m_kind.assign(m_columns.size(), Cell::Empty);
    m_value.resize(m_columns.size());
    static const std::string kWorld = "0,world,";
    writeRow(kWorld, ws, m_worldSeries);
  }
  if (m_buffer.size() >= kBlock) flushBuffer();
}

void TraceWriter::writeRow(const std::string& who, TraceSeries& series, std::vector<int>& seriesColumns) {
  for (size_t s = 0; s < seriesColumns.size(); ++s)
    if (series.fresh[s]) {
      put(seriesColumns[s], Cell::Exact, series.values[s]);
      series.fresh[s] = 0;
    }
  const int width = int(m_columns.size());
  if (m_widths.empty() || m_widths.back().second != width) m_widths.emplace_back(m_rows, width);
  m_buffer += m_prefix;
  m_buffer += who;
  for (int c = kFirstCell; c < width; ++c) {
    m_buffer += ',';
    const double v = m_value[size_t(c)];
    switch (m_kind[size_t(c)]) {
      case Cell::Empty:
        break;
      case Cell::Real:
        appendReal(m_buffer, v + 0.0);
        break;  // + 0.0: -0 is written 0
      case Cell::Exact:
        appendExact(m_buffer, v);
        break;
      case Cell::Integer:
        appendInteger(m_buffer, (long long)v);
        break;
    }
  }
  m_buffer += '\n';
  ++m_rows;
}

void TraceWriter::flushBuffer() {
  if (m_buffer.empty() || !m_part) return;
  if (std::fwrite(m_buffer.data(), 1, m_buffer.size(), m_part) != m_buffer.size()) m_writeFailed = true;
  m_buffer.clear();
}

bool TraceWriter::finish(World& w, std::string& err) {
  if (!m_part) return true;
  writeRows(w, m_lastStep != w.steps());  // the world's row alone when the step is written
  flushBuffer();
  const bool partOk = std::fclose(m_part) == 0 && !m_writeFailed;
  m_part = nullptr;
  if (!partOk) {
    err = "--trace " + m_path + ": cannot write " + m_partPath + " (disk full?)";
    std::remove(m_partPath.c_str());
    return false;
  }
  // The header, then every row padded with empty cells to the final width.
  std::ifstream in(m_partPath, std::ios::binary);
  std::FILE* out = std::fopen(m_path.c_str(), "wb");
  if (!out || !in) {
    err = "--trace " + m_path + ": cannot write the file (" + std::strerror(errno) + ")";
    if (out) std::fclose(out);
    std::remove(m_partPath.c_str());
    return false;
  }
  const int width = int(m_columns.size());
  m_buffer.clear();
  for (int c = 0; c < width; ++c) {
    if (c) m_buffer += ',';
    m_buffer += csvCell(m_columns[size_t(c)]);
  }
  m_buffer += '\n';
  std::string line;
  size_t segment = 0;
  bool ok = true;
  for (int64_t row = 0; std::getline(in, line); ++row) {
    while (segment + 1 < m_widths.size() && m_widths[segment + 1].first <= row) ++segment;
    m_buffer += line;
    if (!m_widths.empty()) m_buffer.append(size_t(width - m_widths[segment].second), ',');
    m_buffer += '\n';
    if (m_buffer.size() >= kBlock) {
      ok = ok && std::fwrite(m_buffer.data(), 1, m_buffer.size(), out) == m_buffer.size();
      m_buffer.clear();
    }
  }
  ok = ok && std::fwrite(m_buffer.data(), 1, m_buffer.size(), out) == m_buffer.size();
  ok = std::fclose(out) == 0 && ok;
  in.close();
  std::remove(m_partPath.c_str());
  if (!ok) err = "--trace " + m_path + ": cannot write the file (disk full?)";
  return ok;
}

void TraceWriter::discard() {
  if (!m_part) return;
  std::fclose(m_part);
  m_part = nullptr;
  std::remove(m_partPath.c_str());
}

}  // namespace rm3d
