// The connection graph as JSON (run --graph, world.graph()) and Graphviz DOT.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "world/world.h"

namespace rm3d {

std::string World::graphJson() const {
  nlohmann::json j;
  j["time"] = time();
  j["modules"] = nlohmann::json::array();
  for (const Module& m : modules())
    j["modules"].push_back({{"id", m.id}, {"name", m.name}, {"type", m.type->name}});
  j["connections"] = nlohmann::json::array();
  for (const Connection& c : connections())
    j["connections"].push_back(
        {modules()[size_t(c.moduleA)].id, modules()[size_t(c.moduleA)].type->docks[size_t(c.dockA)].name,
         modules()[size_t(c.moduleB)].id, modules()[size_t(c.moduleB)].type->docks[size_t(c.dockB)].name});
  j["components"] = nlohmann::json::array();
  for (const auto& comp : components()) {
    nlohmann::json ids = nlohmann::json::array();
    for (int m : comp) ids.push_back(modules()[size_t(m)].id);
    j["components"].push_back(ids);
  }
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string World::graphDot() const {
  std::string out = "graph rm3d {\n  node [shape=box];\n";
  char line[256];
  for (const Module& m : modules()) {
    std::snprintf(line, sizeof line, "  m%d [label=\"%s\\n%s\"];\n", m.id, m.name.c_str(),
                  m.type->name.c_str());
    out += line;
  }
  for (const Connection& c : connections()) {
    const Module& a = modules()[size_t(c.moduleA)];
    const Module& b = modules()[size_t(c.moduleB)];
    std::snprintf(line, sizeof line, "  m%d -- m%d [taillabel=\"%s\", headlabel=\"%s\"];\n", a.id, b.id,
                  a.type->docks[size_t(c.dockA)].name.c_str(), b.type->docks[size_t(c.dockB)].name.c_str());
    out += line;
  }
  return out + "}\n";
}

}  // namespace rm3d
