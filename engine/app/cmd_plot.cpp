// `rm3d plot FILE.csv --y COLUMN ...`: line plots of a trace (or any CSV with a header row) as
// PNG or SVG, drawn by gnuplot (started with an argument vector, never through a shell). One line
// per y column and module (the `module` column of a trace), against --x (default `time`). A
// `.jsonl` file (rm3d sweep --out) is read as a table too: one row per run, with columns `seed`,
// `exit_code`, `params.<k>` and `metrics.<k>`; its points are drawn as points, or with --mean as
// the mean per x value with the standard deviation as error bars.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/app.h"
#include "app/run_world.h"
#include "script/lua_vm.h"

extern char** environ;

namespace fs = std::filesystem;

namespace rm3d {

namespace {

/// Splits one CSV line into cells (RFC 4180 quoting: "a, ""b""" is `a, "b"`).
std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cells.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cells.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.emplace_back();
    } else if (c != '\r') {
      cells.back() += c;
    }
  }
  return cells;
}

bool parseNumber(const std::string& text, double& v) {
  if (text.empty()) return false;
  char* end = nullptr;
  v = std::strtod(text.c_str(), &end);
  return *end == '\0' && std::isfinite(v);  // nan and inf cells are not points
}

/// Text inside single quotes in a gnuplot script ('' is a quote).
std::string gpQuote(const std::string& text) {
  std::string q = "'";
  for (char c : text) {
    if (c == '\'') q += '\'';
    if (c != '\n' && c != '\r') q += c;
  }
  return q + "'";
}

std::string joined(const std::vector<std::string>& names, size_t max) {
  std::string out;
  for (size_t i = 0; i < names.size() && i < max; ++i) out += (i ? ", " : "") + names[i];
  if (names.size() > max) out += ", ... (" + std::to_string(names.size() - max) + " more)";
  return out;
}

/// A sweep's JSON lines as a table: `seed`, `exit_code`, `params.<k>`, `metrics.<k>` (numbers and
/// booleans as numbers, strings as they are). Empty header and a message on a bad line.
std::string readJsonLines(const std::string& file, std::vector<std::string>& header,
                          std::vector<std::vector<std::string>>& rows) {
  std::ifstream in(file);
  std::string line;
  long long lineNo = 0;
  std::map<std::string, int> column;
  auto cell = [&](std::vector<std::string>& row, const std::string& name, const nlohmann::json& v) {
    std::string text;
    if (v.is_number() || v.is_boolean())
      text = v.is_boolean() ? (v.get<bool>() ? "1" : "0") : v.dump();
    else if (v.is_string())
      text = v.get<std::string>();
    else
      return;
    auto [it, added] = column.emplace(name, int(header.size()));
    if (added) header.push_back(name);
    if (row.size() <= size_t(it->second)) row.resize(size_t(it->second) + 1);
    row[size_t(it->second)] = text;
  };
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.empty()) continue;
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object())
      return file + ":" + std::to_string(lineNo) +
             ": expected a JSON object per line (rm3d sweep --out writes them)";
    std::vector<std::string> row;
    for (const char* key : {"seed", "exit_code"})
      if (j.contains(key)) cell(row, key, j[key]);
    for (const char* group : {"params", "metrics"})
      if (j.contains(group) && j[group].is_object())
        for (const auto& [k, v] : j[group].items()) cell(row, std::string(group) + "." + k, v);
    rows.push_back(std::move(row));
  }
  if (rows.empty()) return file + ": no runs in it (expected JSON lines from rm3d sweep --out)";
  return {};
}

struct Series {
  std::string module;  ///< empty: the file has no module column
  int column;          ///< the y column
  std::vector<std::pair<double, double>> points;
};

int fail(const std::string& message) {
  std::fprintf(stderr, "rm3d plot: %s\n", message.c_str());
  return kExitBadInput;
}

/// Runs gnuplot on `script`; its messages go to our stderr. Empty when it succeeded.
std::string runGnuplot(const std::string& script) {
  const char* argv[] = {"gnuplot", script.c_str(), nullptr};
  pid_t pid = 0;
  const int e = posix_spawnp(&pid, "gnuplot", nullptr, nullptr, const_cast<char* const*>(argv), environ);
  if (e == ENOENT)
    return "gnuplot is not installed (apt-get install gnuplot-nox; .ci/install-deps installs it)";
  if (e != 0) return std::string("cannot start gnuplot (") + std::strerror(e) + ")";
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return {};
  return WIFEXITED(status) ? "gnuplot failed (exit status " + std::to_string(WEXITSTATUS(status)) + ")"
                           : "gnuplot was killed by signal " + std::to_string(WTERMSIG(status));
}

}  // namespace

int plotCommand(const PlotArgs& a) {
  // The output: .png or .svg.
  std::string out = a.out;
  if (out.empty()) out = fs::path(a.file).replace_extension(".png").string();
  const std::string ext = fs::path(out).extension().string();
  if (ext != ".png" && ext != ".svg")
    return fail("--out " + out + ": expected a file name ending in .png or .svg");
  int width = 1000, height = 600;
  if (!a.size.empty() && (std::sscanf(a.size.c_str(), "%dx%d", &width, &height) != 2 || width < 64 ||
                          height < 64 || width > 8192 || height > 8192))
    return fail("--size " + a.size + ": expected WIDTHxHEIGHT, 64 to 8192 each, e.g. 1000x600");
  std::string perr;
  if (!checkOutputsApart({{"the input", a.file}}, {{"--out", out}}, perr)) return fail(perr);
  std::error_code ec;
  if (!fs::is_regular_file(a.file, ec))
    return fail(a.file + ": cannot read the file (" +
                (fs::exists(a.file, ec) ? "not a regular file" : "no such file") + ")");
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> table;  // rows after the header
  std::vector<long long> rowLine;               // their line numbers
  const bool sweep = fs::path(a.file).extension() == ".jsonl";
  if (sweep) {
    const std::string err = readJsonLines(a.file, header, table);
    if (!err.empty()) return fail(err);
  } else {
    std::ifstream in(a.file);
    std::string line;
    if (!std::getline(in, line) || line.empty())
      return fail(a.file + ": empty, expected a CSV file with a header row (rm3d run --trace writes one)");
    header = splitCsv(line);
    // Column names end up in messages and the picture: text only (the UTF-8 rule).
    std::string shown = line;
    makeValidUtf8(shown);
    const bool control = std::any_of(line.begin(), line.end(),
                                     [](char c) { return (unsigned char)c < 32 && c != '\t' && c != '\r'; });
    if (shown != line || control)
      return fail(a.file +
                  ":1: the header row is not UTF-8 text (expected a CSV file with a header row of column "
                  "names; rm3d run --trace writes one)");
    long long rowNo = 1;
    while (std::getline(in, line)) {
      ++rowNo;
      if (line.empty()) continue;
      table.push_back(splitCsv(line));
      rowLine.push_back(rowNo);
    }
  }
  const auto columnOf = [&](const std::string& name) -> int {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return int(i);
    return -1;
  };
  const auto unknown = [&](const char* flag, const std::string& name) {
    return fail(std::string(flag) + " " + name + ": no column '" + name + "' in " + a.file +
                " (columns: " + joined(header, 60) + ")");
  };
  const std::string xName = a.x.empty() ? (columnOf("time") >= 0            ? "time"
                                           : sweep && columnOf("seed") >= 0 ? "seed"
                                                                            : header[0])
                                        : a.x;
  const int xCol = columnOf(xName);
  if (xCol < 0) return unknown("--x", xName);
  std::vector<int> yCols;
  for (const std::string& y : a.y) {
    const int c = columnOf(y);
    if (c < 0) return unknown("--y", y);
    yCols.push_back(c);
  }
  const int moduleCol = columnOf(a.by.empty() ? "module" : a.by);
  const int idCol = a.by.empty() ? columnOf("module_id") : -1;
  if (!a.by.empty() && moduleCol < 0) return unknown("--by", a.by);

  // One series per (y column, module), in the order modules first appear.
  std::vector<std::string> modules;  // every module in the file (for messages)
  std::vector<Series> series;
  std::vector<char> matched(a.modules.size(), 0);  // per --module: some row was theirs
  const auto wanted = [&](const std::vector<std::string>& row) {
    if (a.modules.empty() || moduleCol < 0) return true;
    for (size_t k = 0; k < a.modules.size(); ++k)
      if (row[size_t(moduleCol)] == a.modules[k] || (idCol >= 0 && row[size_t(idCol)] == a.modules[k])) {
        matched[k] = 1;
        return true;
      }
    return false;
  };
  for (size_t r = 0; r < table.size(); ++r) {
    std::vector<std::string>& row = table[r];
    if (row.size() > header.size())
      return fail(a.file + ":" + std::to_string(rowLine[r]) + ": " + std::to_string(row.size()) +
                  " cells, more than the header's " + std::to_string(header.size()));
    row.resize(header.size());
    const std::string module = moduleCol >= 0 ? row[size_t(moduleCol)] : "";
    if (moduleCol >= 0 && std::find(modules.begin(), modules.end(), module) == modules.end())
      modules.push_back(module);
    if (!wanted(row)) continue;
    double x = 0, y = 0;
    if (!parseNumber(row[size_t(xCol)], x)) continue;
    for (int c : yCols) {
      if (!parseNumber(row[size_t(c)], y)) continue;
      auto it = std::find_if(series.begin(), series.end(),
                             [&](const Series& s) { return s.column == c && s.module == module; });
      if (it == series.end()) it = series.insert(series.end(), Series{module, c, {}});
      it->points.emplace_back(x, y);
    }
  }
  for (size_t k = 0; k < a.modules.size(); ++k)
    if (moduleCol >= 0 && !matched[k])
      return fail("--module " + a.modules[k] + ": no rows for module '" + a.modules[k] + "' in " + a.file +
                  " (modules: " + joined(modules, 40) + ")");
  if (series.empty())
    return fail("nothing to plot in " + a.file + ": no row has finite numbers in both --x " + xName +
                " and --y " + joined(a.y, 10) +
                (a.modules.empty() ? "" : " for --module " + joined(a.modules, 10)));

  // --mean: one point per x value, the mean of its y values, with their standard deviation.
  std::vector<std::vector<double>> spread(series.size());
  if (a.mean) {
    for (size_t i = 0; i < series.size(); ++i) {
      std::map<double, std::pair<double, std::vector<double>>> byX;
      for (const auto& [x, y] : series[i].points) byX[x].second.push_back(y);
      series[i].points.clear();
      for (auto& [x, ys] : byX) {
        double sum = 0, sq = 0;
        for (double y : ys.second) sum += y;
        const double mean = sum / double(ys.second.size());
        for (double y : ys.second) sq += (y - mean) * (y - mean);
        series[i].points.emplace_back(x, mean);
        spread[i].push_back(ys.second.size() > 1 ? std::sqrt(sq / double(ys.second.size() - 1)) : 0.0);
      }
    }
  }
  const char* style = a.mean ? "yerrorlines" : sweep ? "points pt 7 ps 0.6" : "lines";

  std::string err;
  if (!prepareOutputFile("--out", out, err)) return fail(err);
  // Data (one block per series) and script, beside the output while gnuplot runs.
  const std::string dataFile = out + ".data.tmp", scriptFile = out + ".gp.tmp";
  {
    std::ofstream d(dataFile);
    for (size_t i = 0; i < series.size(); ++i) {
      for (size_t k = 0; k < series[i].points.size(); ++k) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g\n", series[i].points[k].first,
                      series[i].points[k].second, a.mean ? spread[i][k] : 0.0);
        d << buf;
      }
      d << "\n\n";
    }
    std::ofstream g(scriptFile);
    g << (ext == ".png" ? "set terminal pngcairo" : "set terminal svg") << " size " << width << "," << height
      << " noenhanced\n";
    g << "set output " << gpQuote(out) << "\n";
    if (!a.title.empty()) g << "set title " << gpQuote(a.title) << "\n";
    g << "set xlabel "
      << gpQuote(!a.xlabel.empty() ? a.xlabel
                 : xName == "time" ? "time (s)"
                                   : xName)
      << "\n";
    g << "set ylabel " << gpQuote(a.ylabel.empty() ? (a.y.size() == 1 ? a.y[0] : "") : a.ylabel) << "\n";
    g << "set grid\n";
    // Points and error bars (a sweep, --mean) at the ends of the range would sit on the frame; a
    // line's highest and lowest values too, where they fall on a tic: 5% of room above and below.
    if (sweep || a.mean)
      g << "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n";
    else
      g << "set offsets 0, 0, graph 0.05, graph 0.05\n";
    if (series.size() > 16)
      g << "unset key\n";
    else
      g << "set key below\n";
    g << "plot ";
    for (size_t i = 0; i < series.size(); ++i) {
      const Series& s = series[i];
      std::string title = header[size_t(s.column)];
      if (!s.module.empty()) {
        const std::string group = a.by.empty() ? s.module : a.by + " = " + s.module;
        title = a.y.size() == 1 ? group : group + ": " + title;
      }
      g << (i ? ", \\\n     " : "") << gpQuote(dataFile) << " index " << i << " using "
        << (a.mean ? "1:2:3" : "1:2") << " with " << style << " title "
        << gpQuote(a.mean ? "mean " + title : title);
    }
    g << "\n";
    if (!d || !g) {
      std::remove(dataFile.c_str());
      std::remove(scriptFile.c_str());
      return fail("--out " + out + ": cannot write beside it (" + dataFile + ")");
    }
  }
  err = runGnuplot(scriptFile);
  std::remove(dataFile.c_str());
  std::remove(scriptFile.c_str());
  if (err.empty() && fs::file_size(out, ec) == 0) err = "gnuplot wrote nothing to " + out;
  if (!err.empty()) return fail(err);
  size_t points = 0;
  for (const Series& s : series) points += s.points.size();
  std::printf("wrote %s: %zu lines, %zu points\n", out.c_str(), series.size(), points);
  return kExitOk;
}

}  // namespace rm3d
