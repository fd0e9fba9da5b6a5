#include "rfem/studies/validity.hpp"

#include <fmt/core.h>

#include <cmath>

#include "rfem/core/check.hpp"

namespace rfem {

ValidityMonitor::ValidityMonitor(const Model& model) : model_(model) {
  for (const MountedLink& L : model.links) links_.push_back({L.name});
}

void ValidityMonitor::check(const VecX& q, double t) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model_.dof(), "q");
  for (size_t l = 0; l < links_.size(); ++l) {
    Link& s = links_[l];
    const int n = model_.links[l].n();
    for (int k = 0; k < n; ++k) {
      const double phi = q.segment<3>(model_.rfe_index(static_cast<int>(l), k) + 3).cwiseAbs().maxCoeff();
      if (phi > s.peak) {
        s.peak = phi;
        s.peak_t = t;
        s.peak_rfe = k;
      }
      if (phi > kSmallRotation && !s.exceeded) {
        s.exceeded = true;
        s.first_t = t;
      }
    }
  }
}

std::vector<std::string> ValidityMonitor::warnings(const std::string& context) const {
  std::vector<std::string> out;
  for (const Link& s : links_) {
    if (!s.exceeded) continue;
    const double err = 0.5 * s.peak * s.peak;
    const std::string when = std::isnan(s.peak_t) ? std::string() : fmt::format(" at t = {:g} s", s.peak_t);
    const std::string first = std::isnan(s.first_t) ? std::string() : fmt::format(" from t = {:g} s", s.first_t);
    out.push_back(fmt::format("{}link '{}': rfe {} turned {:.3g} rad relative to {{r}}{} (beyond {} rad{}): outside the small "
                              "deformation the model is built on, its linearisation errs by about phi^2/2 = {:.2g} % there; "
                              "the results are approximate",
                              context.empty() ? "" : context + ": ", s.name, s.peak_rfe + 1, s.peak, when, kSmallRotation, first,
                              100 * err));
  }
  return out;
}

}  // namespace rfem
