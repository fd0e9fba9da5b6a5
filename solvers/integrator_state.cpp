// The ESDIRK integrator's state as a vector of doubles (a checkpoint's payload) and back. Counters
// and indices are stored as doubles: exact below 2⁵³.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "integrator.hpp"

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
  // Counters and sizes are whole numbers ≥ 0 (below 2⁵³), every value is finite: a damaged or edited
  // state is refused here, naming the entry, not at the first step.
  const auto whole = [&](size_t i, const char* name) {
    if (!(x[i] >= 0 && x[i] <= 9007199254740992.0 && x[i] == std::floor(x[i])))
      throw std::invalid_argument(std::string("the state's ") + name + " is not a whole number ≥ 0 (" + std::to_string(x[i]) + ")");
    return x[i];
  };
  const double stored = whole(head - 1, "count of unknowns");
  if (unknowns < 0) unknowns = static_cast<int>(std::min(stored, 1e9));  // (not checked here)
  if (stored != unknowns)
    throw std::invalid_argument("the state has " + std::to_string(static_cast<long>(stored)) + " unknowns, the model " +
                                std::to_string(unknowns) + ": not a state of this model");
  const size_t want = head + 3 * static_cast<size_t>(unknowns);
  if (x.size() != want)
    throw std::invalid_argument("the state of " + std::to_string(unknowns) + " unknowns has " + std::to_string(x.size()) +
                                " values where it needs " + std::to_string(want) + ": cut or padded");
  static const char* names[kScalars + 1] = {"version", "t", "h", "err_prev", "eta", "dissipated", "input_work",
                                            "power.dissipation", "power.input", "next_output", "steps",
                                            "residual_evals", "factorizations", "newton_iters", "newton_fails",
                                            "error_test_fails", "last_step"};
  for (size_t i = 1; i < head - 1; ++i) {
    // (h may be +inf: between a caller's frequent stops the step controller's proposal grows without
    // bound while every step lands on the next stop; the next step is cut to its stop all the same)
    if (i == 2 && x[i] == INFINITY) continue;
    if (!std::isfinite(x[i])) throw std::invalid_argument(std::string("the state's ") + names[i] + " is not finite");
    if (i >= 9 && i <= 15) whole(i, names[i]);
  }
  if (x[1] < 0) throw std::invalid_argument("the state's time t = " + std::to_string(x[1]) + " s is negative");
  if (x[2] < 0) throw std::invalid_argument("the state's next step size h is negative");
  const char* parts[3] = {"q", "v", "a"};
  for (size_t k = head; k < x.size(); ++k)
    if (!std::isfinite(x[k]))
      throw std::invalid_argument(std::string("the state's ") + parts[(k - head) / static_cast<size_t>(unknowns)] + "[" +
                                  std::to_string((k - head) % static_cast<size_t>(unknowns)) + "] is not finite");
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
