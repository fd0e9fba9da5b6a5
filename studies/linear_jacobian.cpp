#include "linear_jacobian.hpp"

#include <algorithm>
#include <array>
#include <utility>

#include "../core/check.hpp"

namespace rfem {

namespace {

// A difference quotient: Σ_s w_s (f(x + d_s e) − f(x)), as (d_s, w_s).
using Difference = std::vector<std::pair<double, double>>;

// The part of an rfe's moments its node rows read (generalised_forces sets no Y or G for rfes).
struct Wrench {
  Vec3 f = Vec3::Zero(), n = Vec3::Zero();
  Vec4 s = Vec4::Zero();
};

class Evaluator {
 public:
  Evaluator(const Model& model, const std::vector<JointInput>& inputs, const ForceTerms& terms, double t, const VecX& q,
            const VecX& v, const VecX& a)
      : md_(model), in_(inputs), terms_(terms), t_(t), x_{q, v, a}, base_{q, v, a}, ws_(model, Parallelism{1, 256, 1}) {
    RFEM_CHECK_ARGUMENT_SIZE(inputs.size(), model.m(), "inputs");
    for (const VecX* y : {&q, &v, &a}) RFEM_CHECK_ARGUMENT_SIZE(y->size(), model.dof(), "state");
    evaluate();
    F0_ = F_;
    tau0_ = tau_;
    mom0_ = mom_;
    bk0_ = ws_.bk;
  }

  // Σ_s w_s (F(x + d_s e_C) − F(x)) for the coordinates C of one kind (0 q, 1 v, 2 q̈), with the
  // torques' and (if `wrenches`) every rfe's moments' alike.
  void differ(int kind, const std::vector<int>& coords, const Difference& diff, bool wrenches) {
    dF_.setZero(md_.dof());
    dtau_.setZero(md_.m());
    if (wrenches) dmom_.assign(mom0_.size(), Wrench{});
    VecX& x = x_[kind];
    for (const auto& [d, w] : diff) {
      for (int c : coords) x[c] += d;
      evaluate();
      for (int c : coords) x[c] = base_[kind][c];
      dF_ += w * (F_ - F0_);
      dtau_ += w * (tau_ - tau0_);
      if (wrenches)
        for (size_t c = 0; c < mom_.size(); ++c) {
          dmom_[c].f += w * (mom_[c].f - mom0_[c].f);
          dmom_[c].n += w * (mom_[c].n - mom0_[c].n);
          dmom_[c].s += w * (mom_[c].s - mom0_[c].s);
        }
    }
  }

  const VecX& dF() const { return dF_; }
  const VecX& dtau() const { return dtau_; }
  const VecX& tau0() const { return tau0_; }
  const Wrench& dmom(int chunk) const { return dmom_[static_cast<size_t>(chunk)]; }
  const BaseKinematics& bk0() const { return bk0_; }
  int evaluations() const { return evaluations_; }
  const Workspace& ws() const { return ws_; }

 private:
  void evaluate() {
    generalised_forces(md_, x_[0], x_[1], x_[2], terms_, F_, nullptr, &ws_);
    ++evaluations_;
    tau_.resize(md_.m());
    for (int j = 0; j < md_.m(); ++j) {
      const int c = md_.joint_index(j);
      tau_[j] = in_[j].prescribed() ? F_[c] : in_[j].torque->at(t_, x_[0][c], x_[1][c]);
    }
    mom_.resize(ws_.moments.size());
    for (size_t c = 0; c < mom_.size(); ++c) mom_[c] = {ws_.moments[c].f, ws_.moments[c].n, ws_.moments[c].s};
  }

  const Model& md_;
  const std::vector<JointInput>& in_;
  ForceTerms terms_;
  double t_;
  std::array<VecX, 3> x_, base_;
  Workspace ws_;
  VecX F_, tau_, F0_, tau0_, dF_, dtau_;
  std::vector<Wrench> mom_, mom0_, dmom_;
  BaseKinematics bk0_;
  int evaluations_ = 0;
};

}  // namespace

EquationsJacobian equations_jacobian(const Model& model, const std::vector<JointInput>& inputs, const ForceTerms& terms,
                                     double t, const VecX& q, const VecX& v, const VecX& a) {
  Evaluator ev(model, inputs, terms, t, q, v, a);
  const int n6 = model.flexible_dofs(), m = model.m();
  // The unknowns (EquationsOfMotion's order): every rfe coordinate, then the free joints.
  std::vector<int> ucoord, row_of(static_cast<size_t>(model.dof()), -1), free_joint_of_row;
  for (int i = 0; i < n6; ++i) ucoord.push_back(i);
  free_joint_of_row.assign(static_cast<size_t>(n6), -1);
  for (int j = 0; j < m; ++j)
    if (!inputs[j].prescribed()) {
      ucoord.push_back(model.joint_index(j));
      free_joint_of_row.push_back(j);
    }
  const int U = static_cast<int>(ucoord.size());
  for (int i = 0; i < U; ++i) row_of[static_cast<size_t>(ucoord[i])] = i;

  // Columns perturbed one at a time (free joints, carrying rfes and their neighbours), and the
  // groups of rfes three apart (link, rfe) perturbed together.
  std::vector<int> single;
  std::array<std::vector<std::pair<int, int>>, 3> groups;
  for (int j = 0; j < m; ++j)
    if (!inputs[j].prescribed()) single.push_back(row_of[static_cast<size_t>(model.joint_index(j))]);
  std::vector<int> chunk_of_first(model.links.size(), 0);  // chunks are single rfes, link by link
  {
    const auto& ch = ev.ws().chunk;
    for (size_t c = 0; c < ch.size(); ++c)
      if (ch[c].begin == 0) chunk_of_first[static_cast<size_t>(ch[c].link)] = static_cast<int>(c);
  }
  for (size_t l = 0; l < model.links.size(); ++l) {
    const MountedLink& L = model.links[l];
    for (int k = 0; k < L.n(); ++k) {
      const bool near_carrier = L.carries(k) || (k > 0 && L.carries(k - 1)) || (k + 1 < L.n() && L.carries(k + 1));
      if (near_carrier)
        for (int b = 0; b < 6; ++b) single.push_back(model.rfe_index(static_cast<int>(l), k) + b);
      else
        groups[static_cast<size_t>(k % 3)].emplace_back(static_cast<int>(l), k);
    }
  }

  EquationsJacobian J;
  J.tau0 = ev.tau0();
  J.coords = ucoord;
  const auto rich = richardson();
  const Difference central(rich.begin(), rich.end());
  const Difference unit = {{1.0, 1.0}};  // r is linear in q̈: one unit step, exact up to round-off
  const Difference diffs[3] = {central, central, unit};
  SparseMat* mats[3] = {&J.K, &J.D, &J.M};
  MatX* taus[3] = {&J.tau_q, &J.tau_v, &J.tau_a};
  VecX node_rows = VecX::Zero(model.dof());
  for (int kind = 0; kind < 3; ++kind) {
    std::vector<Eigen::Triplet<double>> tr;
    MatX& tau = *taus[kind];
    tau = MatX::Zero(m, U);
    auto put = [&](int row, int col, double val) {
      if (val != 0.0) tr.emplace_back(row, col, val);
    };
    for (int col : single) {
      ev.differ(kind, {ucoord[static_cast<size_t>(col)]}, diffs[kind], false);
      for (int i = 0; i < U; ++i) {
        const int j = free_joint_of_row[static_cast<size_t>(i)];
        put(i, col, ev.dF()[ucoord[static_cast<size_t>(i)]] - (j >= 0 ? ev.dtau()[j] : 0.0));
      }
      tau.col(col) = ev.dtau();
    }
    for (const auto& group : groups)
      for (int axis = 0; axis < 6; ++axis) {
        if (group.empty()) continue;
        std::vector<int> coords;
        for (const auto& [l, k] : group) coords.push_back(model.rfe_index(l, k) + axis);
        ev.differ(kind, coords, diffs[kind], true);
        for (const auto& [l, k] : group) {
          const MountedLink& L = model.links[static_cast<size_t>(l)];
          const int col = model.rfe_index(l, k) + axis;
          for (int kk = std::max(0, k - 1); kk <= std::min(L.n() - 1, k + 1); ++kk)
            for (int b = 0; b < 6; ++b) put(model.rfe_index(l, kk) + b, col, ev.dF()[model.rfe_index(l, kk) + b]);
          if (L.parent < 0) continue;
          const std::vector<int>& path = model.nodes[static_cast<size_t>(L.parent)].path;
          for (int i : path) node_rows[model.nodes[static_cast<size_t>(i)].coord] = 0.0;
          const Wrench& w = ev.dmom(chunk_of_first[static_cast<size_t>(l)] + k);
          BaseMoments bm;
          bm.f = w.f;
          bm.n = w.n;
          bm.s = w.s;
          add_link_moments_to_nodes(model, ev.bk0(), l, bm, terms, node_rows);
          for (int i : path) {
            const Node& nd = model.nodes[static_cast<size_t>(i)];
            const int row = row_of[static_cast<size_t>(nd.coord)];
            if (row >= 0) put(row, col, node_rows[nd.coord]);  // (a free joint's law sees its own joint only)
            if (nd.joint >= 0 && inputs[static_cast<size_t>(nd.joint)].prescribed()) tau(nd.joint, col) = node_rows[nd.coord];
          }
        }
      }
    mats[kind]->resize(U, U);
    mats[kind]->setFromTriplets(tr.begin(), tr.end());
  }
  J.evaluations = ev.evaluations();
  return J;
}

}  // namespace rfem
