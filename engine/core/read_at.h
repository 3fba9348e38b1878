// A value of type T read from byte `at` of an object whose fields are another library's (the
// places in physics/bullet_layout.h and script/lua_layout.h), without assuming its alignment.
#pragma once

#include <cstring>

namespace rm3d {

template <class T>
T readAt(const void* p, int at) {
  T v;
  std::memcpy(&v, static_cast<const char*>(p) + at, sizeof v);
  return v;
}

}  // namespace rm3d
