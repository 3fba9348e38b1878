// Whether a second thread pays for a long tree's halves (ExactSolver::splitTree), by the clock.
//
// Which thread solves a half changes no bit, so the choice may follow measured time. It does not
// always pay: a substep hands over a few hundred halves, and on a machine whose two cores pass
// data slowly (a round trip of 0.5 us), a 150-module snake ran at 269 steps/s on two threads
// against 398 on one. Both ways are timed, in turn at first; then the faster by its recent
// average is taken, and the other again once every kProbe calls, so that a change is seen.
#pragma once

namespace rm3d {

class HalfPace {
 public:
  static constexpr int kFirst = 3;   ///< calls each way, in turn, before choosing
  static constexpr int kProbe = 32;  ///< the way not taken, once in this many calls

  /// Whether this call takes the helper.
  bool helped() {
    ++m_calls;
    if (m_count[0] < kFirst || m_count[1] < kFirst) return m_count[1] <= m_count[0];
    const bool faster = m_average[1] < m_average[0];
    return m_calls % kProbe == 0 ? !faster : faster;
  }
  /// What the call took, s.
  void took(bool helped, double seconds) {
    double& a = m_average[helped];
    a = m_count[helped]++ == 0 ? seconds : a + 0.25 * (seconds - a);
  }

 private:
  double m_average[2] = {0, 0};  ///< s: alone, helped (exponential, about the last 4 calls)
  int m_count[2] = {0, 0};
  long m_calls = 0;
};

}  // namespace rm3d
