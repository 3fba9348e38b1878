// The connection graph as JSON (`run --graph`, world.graph()) and Graphviz DOT.
#pragma once

#include <string>

namespace rm3d {

class World;

/// The connection graph now: {"time", "modules": [{id, name, type}], "connections": [[idA, dockA,
/// idB, dockB]], "components": [[ids]]}.
std::string graphJson(const World& w);
/// The same graph in Graphviz DOT (modules as boxes, docks as edge labels).
std::string graphDot(const World& w);

}  // namespace rm3d
