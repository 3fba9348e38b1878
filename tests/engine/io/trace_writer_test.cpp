// The --trace writer: rows at the traced steps, columns added as they appear with earlier rows
// padded to the final width, series taken once ("latest since the last row"), the world's row
// only when one of its series was recorded, and names quoted for CSV.
#include "io/trace_writer.h"

#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "test_world.h"

using namespace rm3d;
using rm3d::test::makeWorld;

namespace {

std::vector<std::vector<std::string>> readCsv(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells(1);
    for (char c : line) {
      if (c == ',')
        cells.emplace_back();
      else
        cells.back().push_back(c);
    }
    rows.push_back(cells);
  }
  return rows;
}

int columnOf(const std::vector<std::string>& header, const std::string& name) {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return int(i);
  return -1;
}

}  // namespace

TEST_CASE("trace: traced steps, late columns padded, series taken once, world rows when recorded") {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rm3d_trace_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "t.csv").string();
  auto w = makeWorld(R"(
    world.set{duration = 1}
    world.spawn("superbot", {at = {0, 0, 0.1}, name = "m", fixed = true})
    world.on_step(function(t)
      local step = math.floor(t / world.dt() + 0.5)
      if step == 3 then world.trace("late", 3) end
    end)
  )");
  TraceWriter trace;
  std::string err;
  REQUIRE(trace.open(path, 2, err));
  trace.sample(*w);
  for (int i = 0; i < 5; ++i) {
    w->step();
    trace.sample(*w);
  }
  REQUIRE(trace.finish(*w, err));
  CHECK_FALSE(std::filesystem::exists(path + ".part"));
  const auto rows = readCsv(path);
  REQUIRE(rows.size() == 6);  // header; module rows at steps 0, 2, 4 and the last, 5; one world row
  const auto& header = rows[0];
  const int late = columnOf(header, "trace.late"), step = columnOf(header, "step"),
            id = columnOf(header, "module_id");
  REQUIRE(late == int(header.size()) - 1);  // appeared last, at step 3
  for (const auto& r : rows) CHECK(r.size() == header.size());
  std::vector<std::string> steps;
  for (size_t i = 1; i < rows.size(); ++i) steps.push_back(rows[i][size_t(step)] + ":" + rows[i][size_t(id)]);
  CHECK(steps == std::vector<std::string>{"0:1", "2:1", "4:1", "4:0", "5:1"});
  CHECK(rows[4][size_t(late)] == "3");  // the world row after step 3's record
  CHECK(rows[4][3] == "world");
  CHECK(rows[5][size_t(late)].empty());  // a module row has no world series
  CHECK(trace.rows() == 5);
  std::filesystem::remove_all(dir);
}

TEST_CASE("trace: CSV cells for names") {
  CHECK(csvCell("snake_1") == "snake_1");
  CHECK(csvCell("a, \"b\"") == "\"a, \"\"b\"\"\"");
  CHECK(csvCell("two\nlines") == "two lines");
}
