// The ESDIRK integrator's state as a vector of doubles (a checkpoint's payload) and back. Counters
// and indices are stored as doubles: exact below 2⁵³.
#include <stdexcept>

#include "rfem/solvers/integrator.hpp"

namespace rfem {

namespace {
constexpr double kVersion = 1.0;
constexpr int kScalars = 16;  // version … error_test_fails below; then last_step and the unknowns
}  // namespace

std::vector<double> IntegratorState::pack() const {
  std::vector<double> x = pack_head();
  x.reserve(x.size() + q.size() + v.size() + a.size());
  x.insert(x.end(), q.data(), q.data() + q.size());
  x.insert(x.end(), v.data(), v.data() + v.size());
  x.insert(x.end(), a.data(), a.data() + a.size());
  return x;
}

std::vector<double> IntegratorState::pack_head() const {
  const IntegratorStats& s = stats;
  std::vector<double> x = {kVersion,
                           t,
                           h,
                           err_prev,
                           eta,
                           dissipated,
                           input_work,
                           power.dissipation,
                           power.input,
                           static_cast<double>(next_output),
                           static_cast<double>(s.steps),
                           static_cast<double>(s.residual_evals),
                           static_cast<double>(s.factorizations),
                           static_cast<double>(s.newton_iters),
                           static_cast<double>(s.newton_fails),
                           static_cast<double>(s.error_test_fails)};
  x.push_back(s.last_step);
  x.push_back(static_cast<double>(q.size()));
  return x;
}

IntegratorState IntegratorState::unpack(const std::vector<double>& x, int unknowns) {
  const size_t head = kScalars + 2;
  if (x.size() < head || x[0] != kVersion)
    throw std::invalid_argument("the checkpoint is not an integrator state of this version of rfem");
  if (unknowns < 0 && x[head - 1] >= 0) unknowns = static_cast<int>(x[head - 1]);  // (not checked here)
  if (x[head - 1] != unknowns || x.size() != head + 3 * static_cast<size_t>(unknowns))
    throw std::invalid_argument("the checkpoint has " + std::to_string(static_cast<long>(x[head - 1])) +
                                " unknowns, the model " + std::to_string(unknowns) + ": not a state of this model");
  IntegratorState st;
  size_t i = 1;
  auto next = [&] { return x[i++]; };
  auto count = [&] { return static_cast<long>(next()); };
  st.t = next();
  st.h = next();
  st.err_prev = next();
  st.eta = next();
  st.dissipated = next();
  st.input_work = next();
  st.power.dissipation = next();
  st.power.input = next();
  st.next_output = count();
  st.stats.steps = count();
  st.stats.residual_evals = count();
  st.stats.factorizations = count();
  st.stats.newton_iters = count();
  st.stats.newton_fails = count();
  st.stats.error_test_fails = count();
  st.stats.last_step = next();
  ++i;  // (the unknowns, checked above)
  const Eigen::Index u = unknowns;
  st.q = Eigen::Map<const VecX>(x.data() + i, u);
  st.v = Eigen::Map<const VecX>(x.data() + i + u, u);
  st.a = Eigen::Map<const VecX>(x.data() + i + 2 * u, u);
  return st;
}

}  // namespace rfem
