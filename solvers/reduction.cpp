#include "rfem/solvers/reduction.hpp"

#include <stdexcept>

#include "rfem/solvers/modes.hpp"

namespace rfem {

Reduction::Reduction(const Model& model, const VecX& qb) : full_rfe_(model.flexible_dofs()) {
  std::vector<char> reduced(full_rfe_, 0);
  for (size_t l = 0; l < model.links.size(); ++l) {
    const MountedLink& L = model.links[l];
    if (L.d.modes <= 0) continue;
    LinkModes lm = link_modes(model, static_cast<int>(l), qb, L.d.modes);
    Link r;
    r.link = static_cast<int>(l);
    for (int k = 0; k < L.n(); ++k) {
      r.rfe.push_back(model.rfe_index(static_cast<int>(l), k));
      for (int a = 1; a < Model::rfe_dofs; ++a) reduced[r.rfe.back() + a] = 1;  // x1 stays an unknown
    }
    r.phi = std::move(lm.shapes);
    r.mass_phi = std::move(lm.mass_shapes);
    r.gram.compute(r.phi.transpose() * r.mass_phi);
    if (r.gram.info() != Eigen::Success)
      throw std::invalid_argument("link " + L.name + ": its " + std::to_string(L.d.modes) +
                                  " modes are not independent without their axial rows: keep fewer");
    r.q0 = std::move(lm.q0);
    r.omega = std::move(lm.omega);
    links_.push_back(std::move(r));
  }
  for (int i = 0; i < full_rfe_; ++i)
    if (!reduced[i]) kept_.push_back(i);
  rfe_ = static_cast<int>(kept_.size());
  for (Link& r : links_) {
    r.first = rfe_;
    rfe_ += static_cast<int>(r.phi.cols());
  }
}

std::shared_ptr<const Reduction> Reduction::of(const Model& model, const VecX& qb) {
  for (const MountedLink& L : model.links)
    if (L.d.modes > 0) return std::make_shared<const Reduction>(model, qb);
  return nullptr;
}

SparseMat Reduction::projector(int k) const {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < static_cast<int>(kept_.size()); ++i) t.emplace_back(kept_[i], i, 1.0);
  for (const Link& r : links_)
    for (size_t e = 0; e < r.rfe.size(); ++e)
      for (int a = 0; a < kModalAxes; ++a)
        for (int c = 0; c < r.phi.cols(); ++c) t.emplace_back(r.rfe[e] + 1 + a, r.first + c, r.phi(kModalAxes * e + a, c));
  for (int j = 0; j < k; ++j) t.emplace_back(full_rfe_ + j, rfe_ + j, 1.0);
  SparseMat P(full_rfe_ + k, rfe_ + k);
  P.setFromTriplets(t.begin(), t.end());
  return P;
}

void Reduction::lift(const double* x, double* xf, int k, bool positions) const {
  for (int i = 0; i < static_cast<int>(kept_.size()); ++i) xf[kept_[i]] = x[i];
  for (const Link& r : links_) {
    const VecX full = r.phi * Eigen::Map<const VecX>(x + r.first, r.phi.cols());
    for (size_t e = 0; e < r.rfe.size(); ++e)
      for (int a = 0; a < kModalAxes; ++a)
        xf[r.rfe[e] + 1 + a] = full[kModalAxes * e + a] + (positions ? r.q0[6 * e + 1 + a] : 0.0);
  }
  for (int j = 0; j < k; ++j) xf[full_rfe_ + j] = x[rfe_ + j];
}

void Reduction::project(const double* rf, double* r, int k) const {
  for (int i = 0; i < static_cast<int>(kept_.size()); ++i) r[i] = rf[kept_[i]];
  for (const Link& l : links_) {
    VecX part(l.phi.rows());
    for (size_t e = 0; e < l.rfe.size(); ++e)
      for (int a = 0; a < kModalAxes; ++a) part[kModalAxes * e + a] = rf[l.rfe[e] + 1 + a];
    Eigen::Map<VecX>(r + l.first, l.phi.cols()) = l.phi.transpose() * part;
  }
  for (int j = 0; j < k; ++j) r[rfe_ + j] = rf[full_rfe_ + j];
}

void Reduction::restrict(const double* xf, double* x, int k, bool positions) const {
  for (int i = 0; i < static_cast<int>(kept_.size()); ++i) x[i] = xf[kept_[i]];
  for (const Link& l : links_) {
    VecX part(l.phi.rows());
    for (size_t e = 0; e < l.rfe.size(); ++e)
      for (int a = 0; a < kModalAxes; ++a)
        part[kModalAxes * e + a] = xf[l.rfe[e] + 1 + a] - (positions ? l.q0[6 * e + 1 + a] : 0.0);
    Eigen::Map<VecX>(x + l.first, l.phi.cols()) = l.gram.solve(l.mass_phi.transpose() * part);
  }
  for (int j = 0; j < k; ++j) x[rfe_ + j] = xf[full_rfe_ + j];
}

SparseMat Reduction::reduce(const BorderedPattern& pattern, const std::vector<double>& values) const {
  return Projection(*this, pattern).reduce(values);
}

Projection::Projection(const Reduction& red, const BorderedPattern& pattern) {
  const BorderedPattern::Csc& csc = pattern.csc();
  const int n = pattern.size();
  std::vector<Eigen::Triplet<double>> t;  // value: the slot, to find each entry's slot below
  t.reserve(2 * csc.rowind.size());
  for (int c = 0; c < n; ++c)
    for (long p = csc.colptr[c]; p < csc.colptr[c + 1]; ++p) {
      const int r = static_cast<int>(csc.rowind[p]);
      t.emplace_back(r, c, static_cast<double>(csc.slot[p]));
      if (r != c) t.emplace_back(c, r, static_cast<double>(csc.slot[p]));
    }
  S_.resize(n, n);
  S_.setFromTriplets(t.begin(), t.end());  // (no duplicates: each entry once per triangle)
  slot_.resize(static_cast<size_t>(S_.nonZeros()));
  for (long k = 0; k < S_.nonZeros(); ++k) slot_[static_cast<size_t>(k)] = static_cast<long>(S_.valuePtr()[k]);
  P_ = red.projector(n - red.full_rfe());
  Pt_ = P_.transpose();
}

SparseMat Projection::reduce(const std::vector<double>& values) {
  double* v = S_.valuePtr();
  for (size_t k = 0; k < slot_.size(); ++k) v[k] = values[static_cast<size_t>(slot_[k])];
  const SparseMat SP = S_ * P_;
  return SparseMat(Pt_ * SP);
}

std::vector<std::string> Reduction::names(const Model& model, const std::vector<std::string>& full_names) const {
  std::vector<std::string> out;
  for (int i : kept_) out.push_back(full_names[i]);
  for (const Link& l : links_)
    for (int c = 0; c < l.phi.cols(); ++c) out.push_back(model.links[l.link].name + "/eta" + std::to_string(c + 1));
  return out;
}

bool ReducedFactor::factorize(const SparseMat& S, bool definite) {
  if (S.nonZeros() != nnz_ || S.rows() != size_) {
    llt_.analyzePattern(S);
    nnz_ = S.nonZeros();
    size_ = static_cast<int>(S.rows());
  }
  llt_.factorize(S);
  if (llt_.info() != Eigen::Success) return false;
  return !definite || (llt_.vectorD().array() > 0.0).all();
}

void ReducedFactor::solve(VecX& b) const { b = llt_.solve(b); }

}  // namespace rfem
