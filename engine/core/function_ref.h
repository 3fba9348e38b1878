// A callable passed down a call, not kept: a pointer to it and a function that calls it.
//
// std::function owns a copy of what it is given and, in libstdc++, allocates one on the heap
// when it holds more than 16 bytes (a lambda capturing three references): the exact solver made
// 130 such allocations a step on a 100-module snake, in calls that only ran a lambda before they
// returned. A FunctionRef never allocates; the callable it refers to must outlive the call it is
// passed to (a lambda written in the call's arguments does).
#pragma once

#include <memory>
#include <type_traits>
#include <utility>

namespace rm3d {

template <class Signature>
class FunctionRef;

template <class R, class... Args>
class FunctionRef<R(Args...)> {
 public:
  FunctionRef() = default;
  template <class Fn, class = std::enable_if_t<!std::is_same_v<std::decay_t<Fn>, FunctionRef> &&
                                               std::is_invocable_r_v<R, Fn&, Args...>>>
  FunctionRef(Fn&& fn) noexcept  // NOLINT(google-explicit-constructor): as std::function
      : m_object(const_cast<void*>(static_cast<const void*>(std::addressof(fn)))),
        m_call([](void* object, Args... args) -> R {
          return (*static_cast<std::remove_reference_t<Fn>*>(object))(std::forward<Args>(args)...);
        }) {}

  R operator()(Args... args) const { return m_call(m_object, std::forward<Args>(args)...); }
  explicit operator bool() const { return m_call != nullptr; }

 private:
  void* m_object = nullptr;
  R (*m_call)(void*, Args...) = nullptr;
};

}  // namespace rm3d
