#include "validity.hpp"

#include "../core/positions.hpp"

#include <stdexcept>

#include <fmt/core.h>

#include <cmath>

#include "../core/check.hpp"

namespace rfem {

ValidityMonitor::ValidityMonitor(const Model& model) : model_(model) {
  for (const MountedLink& L : model.links) links_.push_back({L.name});
  range_.resize(model.joints.size());
  speed_.resize(model.joints.size());
  effort_.resize(model.joints.size());
}

void ValidityMonitor::check_joints(const VecX& q, const VecX& v, const VecX& tau, double t) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model_.dof(), "q");
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), model_.dof(), "v");
  RFEM_CHECK_ARGUMENT_SIZE(tau.size(), model_.m(), "tau");
  auto note = [t](Excess& e, double by) {  // by > 0: beyond the limit by that much
    if (!(by > 0.0)) return;
    if (std::isnan(e.first_t)) e.first_t = t;
    if (by > e.peak) e.peak = by, e.peak_t = t;
  };
  for (int j = 0; j < model_.m(); ++j) {
    const JointLimits& l = model_.joints[static_cast<size_t>(j)].limits;
    const double x = q[model_.joint_index(j)], xd = v[model_.joint_index(j)];
    note(range_[static_cast<size_t>(j)], std::max(l.lower - x, x - l.upper));
    note(speed_[static_cast<size_t>(j)], std::abs(xd) - l.velocity);
    note(effort_[static_cast<size_t>(j)], std::abs(tau[j]) - l.effort);
  }
}

std::string ValidityMonitor::diverged(const VecX& q, double t) const {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model_.dof(), "q");
  for (Eigen::Index i = 0; i < q.size(); ++i)
    if (!std::isfinite(q[i])) return fmt::format("diverged at t = {:.6g} s: coordinate {} is not finite", t, i);
  for (size_t l = 0; l < model_.links.size(); ++l) {
    const MountedLink& L = model_.links[l];
    for (int k = 0; k < L.n(); ++k) {
      const double phi = q.segment<3>(model_.rfe_index(static_cast<int>(l), k) + 3).cwiseAbs().maxCoeff();
      if (phi > kDivergedRotation)
        return fmt::format("diverged at t = {:.6g} s: link '{}': rfe {} turned {:.3g} rad relative to {{r}} (beyond {:.3g} rad: "
                           "no small deformation left; an unstable loop or input?)",
                           t, L.name, k + 1, phi, kDivergedRotation);
    }
    if (L.n() > 0) {
      const Vec3 u = tip_deflection(model_, static_cast<int>(l), q);
      const double off = std::hypot(u[0], u[1]), len = L.d.length;
      if (len > 0 && off > kDivergedDeflection * len)
        return fmt::format("diverged at t = {:.6g} s: link '{}': its tip is {:.3g} m off its undeformed place on a {:.3g} m link "
                           "(an unstable loop or input?)",
                           t, L.name, off, len);
    }
  }
  return {};
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
  for (int j = 0; j < model_.m(); ++j) {
    const Joint& J = model_.joints[static_cast<size_t>(j)];
    const bool rev = J.type == JointType::Revolute;
    const char* u = rev ? "rad" : "m";
    auto say = [&](const Excess& e, const std::string& what, const std::string& unit) {
      if (std::isnan(e.first_t)) return;
      out.push_back(fmt::format("{}joint '{}': {} by up to {:.3g} {} (at t = {:g} s, first at t = {:g} s); rfem does not enforce "
                                "joint limits",
                                context.empty() ? "" : context + ": ", J.name, what, e.peak, unit, e.peak_t, e.first_t));
    };
    const JointLimits& l = J.limits;
    say(range_[static_cast<size_t>(j)], fmt::format("its coordinate left its rated range {:g} to {:g} {}", l.lower, l.upper, u), u);
    say(speed_[static_cast<size_t>(j)], fmt::format("its rate exceeded its rated {:g} {}/s", l.velocity, u), std::string(u) + "/s");
    say(effort_[static_cast<size_t>(j)], fmt::format("its {} exceeded its rated {:g} {}", rev ? "torque" : "force", l.effort, rev ? "N m" : "N"),
        rev ? "N m" : "N");
  }
  return out;
}

std::vector<double> ValidityMonitor::save() const {
  std::vector<double> x;
  for (const Link& L : links_) x.insert(x.end(), {L.peak, L.peak_t, L.first_t, double(L.peak_rfe), L.exceeded ? 1.0 : 0.0});
  for (const auto* v : {&range_, &speed_, &effort_})
    for (const Excess& e : *v) x.insert(x.end(), {e.peak, e.peak_t, e.first_t});
  return x;
}

void ValidityMonitor::restore(const std::vector<double>& x) {
  if (x.size() != 5 * links_.size() + 9 * range_.size())
    throw std::invalid_argument("the checkpoint's validity state is not of this model");
  size_t i = 0;
  for (Link& L : links_) {
    L.peak = x[i++];
    L.peak_t = x[i++];
    L.first_t = x[i++];
    L.peak_rfe = static_cast<int>(x[i++]);
    L.exceeded = x[i++] != 0.0;
  }
  for (auto* v : {&range_, &speed_, &effort_})
    for (Excess& e : *v) {
      e.peak = x[i++];
      e.peak_t = x[i++];
      e.first_t = x[i++];
    }
}

}  // namespace rfem
