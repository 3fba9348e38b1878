// Whether handing a piece of a step's work to other threads pays, by the clock.
//
// Every piece that goes to the worker threads (the behaviours, the narrowphase's pairs, the
// passes over bodies, the solver's batches, a long tree's halves) gives the same bits on one
// thread, so the choice may follow measured time. It does not always pay: on a machine whose two
// cores passed a cache line back and forth in 0.5 us, a 150-module snake ran at 269 steps/s with a
// second thread on its tree's halves against 398 without, and its behaviours took 0.25 ms a step
// on two threads against 0.17 on one. Both ways are timed, in turn at first; then the faster by
// its recent average is taken, and the other again once every kProbe calls, so that a change
// (a scene growing, a machine getting busy) is seen. Each way starts from the least of its first
// calls (the very first may pay for buffers and cold caches); then the way taken averages about
// its last 8 calls and a probe of the other counts for half of that one's. The way taken is kept
// until the other's average is kSwitch of its own or less. (With every way averaging about its
// last 4 calls and no margin, a busy machine's noise flipped the way back and forth, and
// atrons_275's solver batches ran alone in half the calls though alone took 1.21 ms against 0.81
// on the threads; with the first calls averaged, a slow first threaded call kept them alone.)
#pragma once

#include <algorithm>
#include <chrono>

namespace rm3d {

class Pace {
 public:
  static constexpr int kFirst = 3;   ///< calls each way, in turn, before choosing
  static constexpr int kProbe = 64;  ///< the way not taken, once in this many calls
  static constexpr double kSwitch = 0.9;
  static constexpr double kWeight = 0.125;     ///< of a call of the way taken in its average
  static constexpr double kProbeWeight = 0.5;  ///< of a probe in its way's average

  /// Whether this call goes to the threads.
  bool threaded() {
    ++m_calls;
    if (m_count[0] < kFirst || m_count[1] < kFirst) return m_count[1] <= m_count[0];
    if (m_count[0] == kFirst && m_count[1] == kFirst) m_way = m_average[1] < m_average[0];
    if (m_average[!m_way] <= kSwitch * m_average[m_way]) m_way = !m_way;
    return m_calls % kProbe == 0 ? !m_way : m_way;
  }
  /// What the call took, s.
  void took(bool threaded, double seconds) {
    double& a = m_average[threaded];
    if (m_count[threaded] < kFirst)
      a = m_count[threaded] == 0 ? seconds : std::min(a, seconds);
    else
      a += (threaded == m_way ? kWeight : kProbeWeight) * (seconds - a);
    ++m_count[threaded];
  }

 private:
  double m_average[2] = {0, 0};  ///< s: alone, threaded (exponential)
  int m_count[2] = {0, 0};
  bool m_way = false;  ///< the way taken (true: the threads)
  long m_calls = 0;
};

/// Runs threads() or alone(), as `pace` says (always threads() with `always`), and times it;
/// returns whether it took the threads.
template <class Threads, class Alone>
bool runPaced(Pace& pace, bool always, const Threads& threads, const Alone& alone) {
  const bool t = always || pace.threaded();
  const auto start = std::chrono::steady_clock::now();
  if (t)
    threads();
  else
    alone();
  pace.took(t, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return t;
}

}  // namespace rm3d
