// The connection graph as JSON (run --graph, world.graph()) and Graphviz DOT.
#include "io/graph_export.h"

#include <nlohmann/json.hpp>
#include <string>

#include "world/world.h"

namespace rm3d {

std::string graphJson(const World& w) {
  nlohmann::json j;
  j["time"] = w.time();
  j["modules"] = nlohmann::json::array();
  for (const Module& m : w.modules())
    j["modules"].push_back({{"id", m.id}, {"name", m.name}, {"type", m.type->name}});
  j["connections"] = nlohmann::json::array();
  for (const Connection& c : w.connections())
    j["connections"].push_back({w.modules()[size_t(c.moduleA)].id,
                                w.modules()[size_t(c.moduleA)].type->docks[size_t(c.dockA)].name,
                                w.modules()[size_t(c.moduleB)].id,
                                w.modules()[size_t(c.moduleB)].type->docks[size_t(c.dockB)].name});
  j["components"] = nlohmann::json::array();
  for (const auto& comp : w.components()) {
    nlohmann::json ids = nlohmann::json::array();
    for (int m : comp) ids.push_back(w.modules()[size_t(m)].id);
    j["components"].push_back(ids);
  }
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

namespace {

/// Text for a DOT quoted string: `"` and `\` escaped (a backslash would otherwise start a label
/// escape such as \N), a line break as DOT's \n, other control characters as spaces.
std::string dotQuoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

std::string graphDot(const World& w) {
  std::string out = "graph rm3d {\n  node [shape=box];\n";
  for (const Module& m : w.modules())
    out += "  m" + std::to_string(m.id) + " [label=" + dotQuoted(m.name + "\n" + m.type->name) + "];\n";
  for (const Connection& c : w.connections()) {
    const Module& a = w.modules()[size_t(c.moduleA)];
    const Module& b = w.modules()[size_t(c.moduleB)];
    out += "  m" + std::to_string(a.id) + " -- m" + std::to_string(b.id) +
           " [taillabel=" + dotQuoted(a.type->docks[size_t(c.dockA)].name) +
           ", headlabel=" + dotQuoted(b.type->docks[size_t(c.dockB)].name) + "];\n";
  }
  return out + "}\n";
}

}  // namespace rm3d
