// What happened to a dock connection. Every output (summary JSON, world.events(), on_dock,
// recordings, graph export) names it by the contract's words: "engaged", "disengaged", "broken";
// and, before a connection exists, "captured" (a capture joint began drawing two docks together)
// and "stalled" (a capture that has not latched after the docks' capture_time).
#pragma once

#include <cstdint>
#include <string_view>

namespace rm3d {

enum class DockEventKind : uint8_t { Engaged, Disengaged, Broken, Captured, Stalled };

/// The contract's name of a dock event kind.
inline const char* dockEventName(DockEventKind kind) {
  switch (kind) {
    case DockEventKind::Engaged:
      return "engaged";
    case DockEventKind::Disengaged:
      return "disengaged";
    case DockEventKind::Broken:
      return "broken";
    case DockEventKind::Captured:
      return "captured";
    case DockEventKind::Stalled:
      return "stalled";
  }
  return "engaged";
}

/// The kind a name gives (as recordings store it); false for a name that is none of them.
inline bool dockEventKindOf(std::string_view name, DockEventKind& kind) {
  for (DockEventKind k : {DockEventKind::Engaged, DockEventKind::Disengaged, DockEventKind::Broken,
                          DockEventKind::Captured, DockEventKind::Stalled})
    if (name == dockEventName(k)) {
      kind = k;
      return true;
    }
  return false;
}

}  // namespace rm3d
