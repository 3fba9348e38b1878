// `rm3d test`: every world under the given paths (default tests/worlds), headless, one line
// each, then "N passed, N failed"; optionally a JUnit XML report.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/app.h"
#include "app/run_world.h"

namespace fs = std::filesystem;

namespace rm3d {

namespace {

struct Outcome {
  std::string file;
  bool passed;
  double seconds;
  std::string message;
};

std::string xmlEscape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '&': o += "&amp;"; break;
      case '"': o += "&quot;"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t') o += ' ';
        else o += c;
    }
  }
  return o;
}

bool writeJunit(const std::string& path, const std::vector<Outcome>& outcomes) {
  std::ofstream f(path);
  int failures = 0;
  double total = 0;
  for (const Outcome& o : outcomes) {
    failures += o.passed ? 0 : 1;
    total += o.seconds;
  }
  f << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  f << "<testsuites><testsuite name=\"rm3d\" tests=\"" << outcomes.size() << "\" failures=\"" << failures
    << "\" time=\"" << total << "\">\n";
  for (const Outcome& o : outcomes) {
    f << "  <testcase classname=\"worlds\" name=\"" << xmlEscape(o.file) << "\" time=\"" << o.seconds << "\"";
    if (o.passed) {
      f << "/>\n";
    } else {
      f << "><failure message=\"" << xmlEscape(o.message.substr(0, o.message.find('\n'))) << "\">" << xmlEscape(o.message)
        << "</failure></testcase>\n";
    }
  }
  f << "</testsuite></testsuites>\n";
  return bool(f);
}

}  // namespace

int testCommand(const TestArgs& a, const std::string& root) {
  std::vector<std::string> paths = a.paths;
  if (paths.empty()) paths.push_back((fs::path(root) / "tests" / "worlds").string());
  std::vector<std::string> files;
  for (const std::string& p : paths) {
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      std::vector<std::string> found;
      for (const auto& e : fs::recursive_directory_iterator(p, ec))
        if (e.is_regular_file() && e.path().extension() == ".lua") found.push_back(e.path().string());
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(p, ec)) {
      files.push_back(p);
    } else {
      std::fprintf(stderr, "rm3d test: %s: no such file or folder\n", p.c_str());
      return 2;
    }
  }
  std::vector<Outcome> outcomes;
  int passed = 0, failed = 0;
  for (const std::string& file : files) {
    RunOptions o;
    o.projectRoot = root;
    o.threads = a.threads;
    o.strict = a.strict;
    o.echoLog = false;
    WorldRun r = runWorldFile(file, o, std::nullopt, std::nullopt);
    const World& w = *r.world;
    Outcome out{file, r.exitCode == 0, r.wallSeconds, {}};
    if (!r.loadError.empty()) out.message = r.loadError;
    else if (!w.scriptError().empty()) out.message = "world script error: " + w.scriptError();
    else if (!w.divergence().empty()) out.message = w.divergence();
    for (const Failure& f : w.failures()) out.message += (out.message.empty() ? "" : "\n") + f.message;
    if (w.fatalFault())
      for (const Module& m : w.modules())
        if (!m.fault.empty()) out.message += (out.message.empty() ? "" : "\n") + ("fault in " + m.name + ": " + m.fault);
    std::printf("%s %s (%.2f s simulated, %.2f s)\n", out.passed ? "PASS" : "FAIL", file.c_str(), w.time(), r.wallSeconds);
    if (!out.passed) {
      std::string indented = "    " + out.message;
      for (size_t i = 0; (i = indented.find('\n', i)) != std::string::npos; i += 5) indented.replace(i, 1, "\n    ");
      std::printf("%s\n", indented.c_str());
    }
    std::fflush(stdout);
    (out.passed ? passed : failed)++;
    outcomes.push_back(std::move(out));
  }
  if (!a.junit.empty() && !writeJunit(a.junit, outcomes)) {
    std::fprintf(stderr, "rm3d test: cannot write %s\n", a.junit.c_str());
    return 2;
  }
  std::printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}

}  // namespace rm3d
