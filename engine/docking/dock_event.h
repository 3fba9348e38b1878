// What happened to a dock connection. Every output (summary JSON, world.events(), on_dock,
// recordings, graph export) names it by the contract's words: "engaged", "disengaged", "broken".
#pragma once

#include <cstdint>
#include <string_view>

namespace rm3d {

enum class DockEventKind : uint8_t { Engaged, Disengaged, Broken };

/// The contract's name of a dock event kind.
inline const char* dockEventName(DockEventKind kind) {
  switch (kind) {
    case DockEventKind::Engaged:
      return "engaged";
    case DockEventKind::Disengaged:
      return "disengaged";
    case DockEventKind::Broken:
      return "broken";
  }
  return "engaged";
}

/// The kind a name gives (as recordings store it); false for a name that is none of them.
inline bool dockEventKindOf(std::string_view name, DockEventKind& kind) {
  for (DockEventKind k : {DockEventKind::Engaged, DockEventKind::Disengaged, DockEventKind::Broken})
    if (name == dockEventName(k)) {
      kind = k;
      return true;
    }
  return false;
}

}  // namespace rm3d
