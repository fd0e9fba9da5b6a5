#include "modes.hpp"

#include <Spectra/SymEigsShiftSolver.h>
#include <Spectra/SymGEigsShiftSolver.h>
#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/MatOp/SymShiftInvert.h>

#include <Eigen/QR>

#include <algorithm>
#include <memory>
#include <set>

#include <stdexcept>

#include "../assembly/assemble.hpp"
#include "../assembly/rfe_kernels.hpp"
#include "cholmod_solver.hpp"
#include "linear_solver.hpp"
#include "reduction.hpp"
#include "statics.hpp"
#include "../core/check.hpp"

namespace rfem {

std::string to_string(ModeKind k) {
  switch (k) {
    case ModeKind::Axial: return "axial";
    case ModeKind::BendingY: return "bending-y";
    case ModeKind::BendingZ: return "bending-z";
    case ModeKind::Torsion: return "torsion";
    case ModeKind::Rigid: return "rigid";
  }
  return "?";
}

namespace {

// Block-diagonal M_ff and its per-block Cholesky factors.
struct BlockMass {
  std::vector<Mat6> M, L;
};

// Every rfe's own 6×6 mass block, in the order of the coordinates (block i: coordinates 6i … 6i+5).
BlockMass block_mass(const Model& model, const VecX& q) {
  BlockMass bm;
  bm.M.resize(model.n());
  bm.L.resize(model.n());
  BaseKinematics bk;
  const VecX z = VecX::Zero(model.dof());
  base_kinematics(model, q, z, z, bk);
  for (size_t l = 0; l < model.links.size(); ++l) {
    const MountedLink& L = model.links[l];
    for (int k = 0; k < L.n(); ++k) {
      const int at = model.rfe_index(static_cast<int>(l), k), i = at / Model::rfe_dofs;
      RfePose pose;
      rfe_pose(L.d.rfes[k], bk.frame[l], q.segment<6>(at), Vec6::Zero(), Vec6::Zero(), pose, false);
      MatX border;
      Mat4 G;
      rfe_mass_blocks(L.d.rfes[k], pose, bk.Xi, {}, bm.M[i], border, G);
      bm.L[i] = bm.M[i].llt().matrixL();
    }
  }
  return bm;
}

// y = Lᵀ (K − σM)⁻¹ L x: shift-invert operator of the standard problem L⁻¹ K L⁻ᵀ u = λ u.
class ShiftInvertOp {
 public:
  using Scalar = double;
  ShiftInvertOp(const std::shared_ptr<const BorderedPattern>& p, const std::vector<double>& K, const BlockMass& bm)
      : pattern_(*p), K_(K), bm_(bm), solver_(p) {}
  Eigen::Index rows() const { return pattern_.size(); }
  Eigen::Index cols() const { return pattern_.size(); }
  void set_shift(double sigma) {
    std::vector<double> S = K_;
    for (int k = 0; k < pattern_.n_blocks(); ++k)
      for (int l = 0; l < 6; ++l)
        for (int j = 0; j <= l; ++j) S[pattern_.slot(6 * k + j, 6 * k + l)] -= sigma * bm_.M[k](j, l);
    if (!solver_.factorize(S))
      throw std::runtime_error("modal analysis: K − σM is not positive definite (is the link buckled?)");
  }
  void perform_op(const double* x, double* y) const {
    const int n = pattern_.n_blocks();
    VecX b(6 * n);
    for (int k = 0; k < n; ++k) b.segment<6>(6 * k) = bm_.L[k] * Eigen::Map<const Vec6>(x + 6 * k);
    solver_.solve(b);
    for (int k = 0; k < n; ++k) Eigen::Map<Vec6>(y + 6 * k) = bm_.L[k].transpose() * b.segment<6>(6 * k);
  }

 private:
  const BorderedPattern& pattern_;
  const std::vector<double>& K_;
  const BlockMass& bm_;
  CholmodSolver solver_;
};

// With free joints or carrying rfes M is bordered, not block diagonal: the generalised problem K φ = λ M φ in
// Spectra's shift-invert mode, (K − σM)⁻¹ by CHOLMOD and M x on the pattern.
class GeneralShiftInvertOp {
 public:
  using Scalar = double;
  GeneralShiftInvertOp(const std::shared_ptr<const BorderedPattern>& p, const std::vector<double>& K,
                       const std::vector<double>& M)
      : pattern_(*p), K_(K), M_(M), solver_(p) {}
  Eigen::Index rows() const { return pattern_.size(); }
  Eigen::Index cols() const { return pattern_.size(); }
  void set_shift(double sigma) {
    std::vector<double> S = K_;
    for (size_t i = 0; i < S.size(); ++i) S[i] -= sigma * M_[i];
    if (!solver_.factorize(S))
      throw std::runtime_error("modal analysis: K − σM is not positive definite (is the link buckled?)");
  }
  void perform_op(const double* x, double* y) const {
    VecX b = Eigen::Map<const VecX>(x, rows());
    solver_.solve(b);
    Eigen::Map<VecX>(y, rows()) = b;
  }

 private:
  const BorderedPattern& pattern_;
  const std::vector<double>& K_;
  const std::vector<double>& M_;
  CholmodSolver solver_;
};

class MassProductOp {
 public:
  using Scalar = double;
  MassProductOp(const BorderedPattern& p, const std::vector<double>& M) : pattern_(p), M_(M) {}
  Eigen::Index rows() const { return pattern_.size(); }
  Eigen::Index cols() const { return pattern_.size(); }
  void perform_op(const double* x, double* y) const {
    VecX out;
    pattern_.multiply(M_, Eigen::Map<const VecX>(x, rows()), out);
    Eigen::Map<VecX>(y, rows()) = out;
  }

 private:
  const BorderedPattern& pattern_;
  const std::vector<double>& M_;
};

// Runs a Spectra shift-invert solver: its eigenvalues ascending with their vectors (Spectra returns
// the eigenvalues back-transformed, largest 1/(λ−σ) first).
template <class Eigs>
void ascending(Eigs& eigs, VecX& lam, MatX& vectors) {
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12);
  if (eigs.info() != Spectra::CompInfo::Successful) throw std::runtime_error("modal analysis: Lanczos did not converge");
  lam = eigs.eigenvalues().reverse();
  vectors = eigs.eigenvectors().rowwise().reverse();
}

ModeKind classify(const VecX& phi, const BlockMass& bm) {
  double w[4] = {0, 0, 0, 0};  // axial, bending-y (x2, φ3), bending-z (x3, φ2), torsion (φ1)
  static const int kind_of[6] = {0, 1, 2, 3, 2, 1};
  for (size_t k = 0; k < bm.M.size(); ++k)
    for (int i = 0; i < 6; ++i) w[kind_of[i]] += bm.M[k](i, i) * phi[6 * k + i] * phi[6 * k + i];
  int best = 0;
  for (int i = 1; i < 4; ++i)
    if (w[i] > w[best]) best = i;
  return static_cast<ModeKind>(best);
}

// Within a cluster of equal eigenvalues (a beam with Iy = Iz bends alike in both planes) any basis
// is an eigenbasis, and round-off picks one: rotate it to the basis that splits the modes by the
// bending-y weight of classify(), then order them by kind, so the modes of a cluster come out the
// same on every machine. The rotation is orthogonal: the shapes stay M-orthonormal.
void separate_degenerate(const VecX& lambda, MatX& shapes, VecX& uncertainty, const BlockMass& bm) {
  const int count = static_cast<int>(lambda.size());
  static const int kind_of[6] = {0, 1, 2, 3, 2, 1};
  for (int i = 0; i < count;) {
    int j = i + 1;
    while (j < count && std::abs(lambda[j] - lambda[i]) <= 1e-8 * std::max(std::abs(lambda[i]), 1e-300)) ++j;
    const int c = j - i;
    if (c >= 2) {
      MatX P = MatX::Zero(c, c);  // φ_aᵀ W_y φ_b over the cluster
      for (int a = 0; a < c; ++a)
        for (int b = 0; b <= a; ++b) {
          double s = 0.0;
          for (size_t k = 0; k < bm.M.size(); ++k)
            for (int d = 0; d < 6; ++d)
              if (kind_of[d] == 1) s += bm.M[k](d, d) * shapes(6 * k + d, i + a) * shapes(6 * k + d, i + b);
          P(a, b) = P(b, a) = s;
        }
      Eigen::SelfAdjointEigenSolver<MatX> es(P);
      // Most bending-y first (descending weight), each vector's sign fixed by its largest entry.
      const MatX V = es.eigenvectors().rowwise().reverse();
      MatX block = shapes.middleCols(i, c) * V;
      for (int a = 0; a < c; ++a) {
        Eigen::Index at;
        block.col(a).cwiseAbs().maxCoeff(&at);
        if (block(at, a) < 0) block.col(a) = -block.col(a);
      }
      shapes.middleCols(i, c) = block;
      uncertainty.segment(i, c).setConstant(uncertainty.segment(i, c).maxCoeff());
    }
    i = j;
  }
}

}  // namespace

namespace {
ModesResult modes_of(const Model& model, const VecX& qb, const VecX& vb, int count, int dense_limit,
                     const std::vector<int>& free, const Parallelism& parallel);
// K of the modal problem: elastic with its geometric term, gravity, centrifugal at the rates vb.
MatrixTerms stiffness_terms(const VecX& vb) {
  MatrixTerms terms;
  terms.stiffness = 1.0;
  terms.gravity = true;
  terms.inertial = vb.size() > 0 && vb.norm() > 0.0;
  return terms;
}
ModesResult reduced_modes(const Model& model, const Reduction& red, const VecX& qb, const VecX& vb, int count,
                          const std::vector<int>& free, const Parallelism& parallel);
}  // namespace

ModesResult compute_modes(const Model& model, const VecX& qb, const VecX& vb, int count, int dense_limit,
                          const std::vector<int>& free, const Parallelism& parallel) {
  if (model.n() == 0) throw std::invalid_argument("modal analysis needs a flexible link (n ≥ 1)");
  for (const MountedLink& L : model.links)
    if (L.n() == 0) throw std::invalid_argument("modal analysis needs every link flexible (link " + L.name + " has n = 0)");
  RFEM_CHECK_ARGUMENT_SIZE(qb.size(), model.m(), "qb (joint values)");
  if (const auto red = Reduction::of(model, qb, parallel)) return reduced_modes(model, *red, qb, vb, count, free, parallel);
  return modes_of(model, qb, vb, count, dense_limit, free, parallel);
}

namespace {

// x's rotation rows over link l of the sub-model, rfe by rfe: what a reduced link's columns span.
VecX rotation_rows(const Model& sub, int l, const VecX& x) {
  const int n = sub.links[l].n();
  VecX y(kModalAxes * n);
  for (int k = 0; k < n; ++k) y.segment<kModalAxes>(kModalAxes * k) = x.segment<kModalAxes>(sub.rfe_index(l, k) + kModalFirst);
  return y;
}

// Appends r's direction to the orthonormal columns Q if, orthogonalised against them, more than
// kNewDirection · reference of it is left (less is round-off of a direction Q holds); says whether.
bool add_direction(MatX& Q, VecX r, double reference) {
  for (int pass = 0; pass < 2; ++pass) r -= Q * (Q.transpose() * r);  // (twice: classical Gram–Schmidt)
  if (!(r.norm() > kNewDirection * reference)) return false;
  Q.conservativeResize(Q.rows(), Q.cols() + 1);
  Q.col(Q.cols() - 1) = r / r.norm();
  return true;
}

// Static modal derivatives (docs/formulation.md §9) of the picked modes i ≤ j < p of link l of the
// sub-model: K θ_ij = −∂²f/∂η_i∂η_j, f the static forces (sdes, gravity) about the equilibrium
// all.q0 and K = ∂f/∂q there. The second derivative by central differences along φ_i ± φ_j with the
// largest coordinate moved by 1e-3 (m or rad): truncation O(h²), ~1e-6 of the derivative; round-off
// ε|f|/h² far below that. Appended to `out` over the rotation axes like the modes (displacement rows out).
void add_modal_derivatives(const Model& sub, int l, const std::shared_ptr<const BorderedPattern>& pattern,
                           const std::vector<double>& Mv, const ModesResult& all, const std::vector<int>& pick, int p,
                           const Parallelism& parallel, LinkModes& out) {
  const MountedLink& L = sub.links[l];
  const int n = L.n(), N = kModalAxes * n, nf = sub.flexible_dofs();
  const std::vector<int> held(sub.m(), -1);
  const VecX z = VecX::Zero(sub.dof());
  MatrixTerms kt;
  kt.stiffness = 1.0;
  kt.gravity = true;
  std::vector<double> Kv;
  Workspace ws(sub, parallel);
  assemble_matrix(sub, *pattern, held, all.q0, z, kt, Kv, &ws);
  const auto solver = make_linear_solver(LinearSolverKind::Chain, pattern);
  solver->set_threads(parallel.team(sub.n()));
  if (!solver->factorize(Kv))
    throw std::invalid_argument("link " + L.name + ": derivatives need a stiffness that is positive definite about the link's static equilibrium");
  ForceTerms ft;
  ft.inertia = false;
  VecX q, f;
  auto forces = [&](const VecX& d) {
    q = all.q0;
    q.head(nf) += d;
    generalised_forces(sub, q, z, z, ft, f, nullptr, &ws);
    return VecX(f.head(nf));
  };
  // An orthonormal basis of the columns so far: a derivative they (nearly) span adds nothing.
  MatX Q = Eigen::HouseholderQR<MatX>(out.shapes).householderQ() * MatX::Identity(N, out.shapes.cols());
  for (int i = 0; i < p; ++i)
    for (int j = i; j < p; ++j) {
      const VecX a = all.shapes.col(pick[i]).head(nf), b = all.shapes.col(pick[j]).head(nf);
      const double h = 1e-3 / std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff());
      VecX theta = -(forces(h * (a + b)) - forces(h * (a - b)) - forces(h * (b - a)) + forces(-h * (a + b))) / (4 * h * h);
      solver->solve(theta);
      const VecX rot = rotation_rows(sub, l, theta);
      if (!add_direction(Q, rot, rot.norm())) continue;
      const VecX r = Q.col(Q.cols() - 1);
      // The column: its new direction, scaled to a largest coordinate of 1; M_bb of it.
      VecX full = VecX::Zero(nf), Mr;
      for (int k = 0; k < n; ++k) full.segment<kModalAxes>(sub.rfe_index(l, k) + kModalFirst) = r.segment<kModalAxes>(kModalAxes * k);
      const double s = 1.0 / r.cwiseAbs().maxCoeff();
      pattern->multiply(Mv, full, Mr);
      const int c = static_cast<int>(out.shapes.cols());
      out.shapes.conservativeResize(N, c + 1);
      out.mass_shapes.conservativeResize(N, c + 1);
      out.shapes.col(c) = s * r;
      out.mass_shapes.col(c) = s * rotation_rows(sub, l, Mr);
      out.pairs.emplace_back(i + 1, j + 1);
    }
}

}  // namespace

LinkModes link_modes(const Model& model, int l, const VecX& qb, int count, int derivatives, const Parallelism& parallel) {
  RFEM_CHECK_INDEX(l, model.links.size(), "link");
  const MountedLink& L = model.links[l];
  const int n = L.n(), N = kModalAxes * n;
  if (count < 1 || count > N)
    throw std::invalid_argument("link " + L.name + ": modes = " + std::to_string(count) + " must be between 1 and its 3n = " +
                                std::to_string(N) + " rotations");
  if (derivatives < 0 || derivatives > std::min(count, kMaxDerivativeModes))
    throw std::invalid_argument("link " + L.name + ": derivatives = " + std::to_string(derivatives) + " must be between 0 and " +
                                std::to_string(std::min(count, kMaxDerivativeModes)) + " (the modes kept, at most " +
                                std::to_string(kMaxDerivativeModes) + ")");
  std::vector<MountedLink> links;  // this link alone flexible (and not reduced), the others rigid
  for (size_t i = 0; i < model.links.size(); ++i) {
    MountedLink r;
    r.name = model.links[i].name;
    r.d = static_cast<int>(i) == l ? model.links[i].d : model.links[i].d.rigid();
    r.d.modes = 0;
    r.d.derivatives = 0;
    r.on = model.links[i].on;
    links.push_back(std::move(r));
  }
  const Model sub = make_model(model.joints, std::move(links), model.gravity, model.free_base);
  // The first count modes whose rotation rows add a direction to those before them (an axial mode
  // has none; above the bending modes, the shear modes' rotations repeat theirs), and one more: a cut
  // through equal frequencies is refused. At count = 3n the rotations are complete.
  const int N6 = Model::rfe_dofs * n;
  ModesResult all;
  std::vector<int> pick;
  for (int want = std::min(N6, 2 * count + 8);; want = std::min(N6, 2 * want)) {
    all = modes_of(sub, qb, VecX(), want, 2 * want > N6 ? N6 : 600, {}, parallel);
    pick.clear();
    MatX Q(N, 0);  // an orthonormal basis of the picked modes' rotation rows
    for (int i = 0; i < want && static_cast<int>(pick.size()) <= count; ++i) {
      double norm = 0.0;  // of the mode over all its link's coordinates: an axial mode's rotations are round-off of it
      for (int k = 0; k < n; ++k) norm += all.shapes.col(i).segment<Model::rfe_dofs>(sub.rfe_index(l, k)).squaredNorm();
      if (add_direction(Q, rotation_rows(sub, l, all.shapes.col(i)), std::sqrt(norm))) pick.push_back(i);
    }
    if (static_cast<int>(pick.size()) > count || want == N6) break;
  }
  if (static_cast<int>(pick.size()) < count)
    throw std::invalid_argument("link " + L.name + ": modes = " + std::to_string(count) + ": it has only " +
                                std::to_string(pick.size()) + " modes whose rotations are independent");
  if (static_cast<int>(pick.size()) > count &&
      std::abs(all.omega[pick[count]] - all.omega[pick[count - 1]]) <= 1e-6 * all.omega[pick[count]])
    throw std::invalid_argument("link " + L.name + ": modes = " + std::to_string(count) + " keeps one of two equal frequencies (" +
                                std::to_string(all.omega[pick[count]] / (2 * M_PI)) + " Hz): keep " +
                                std::to_string(count - 1) + " or " + std::to_string(count + 1) + " modes");
  const std::vector<int> held(sub.m(), -1);
  const auto shared_pattern = std::make_shared<const BorderedPattern>(sub, held);
  const BorderedPattern& pattern = *shared_pattern;
  MatrixTerms mt;
  mt.mass = 1.0;
  std::vector<double> Mv;
  Workspace ws(sub, parallel);
  assemble_matrix(sub, pattern, held, all.q0, VecX::Zero(sub.dof()), mt, Mv, &ws);
  // The shapes over the coordinates a reduced link's modes span (its displacements stay unknowns of
  // their own) and M_bb Φ_b over them: Φ's displacement rows zeroed first, so M_bb Φ_b alone.
  LinkModes out;
  out.omega.resize(count);
  out.shapes.resize(N, count);
  out.mass_shapes.resize(N, count);
  for (int c = 0; c < count; ++c) {
    out.omega[c] = all.omega[pick[c]];
    VecX phi = all.shapes.col(pick[c]), Mphi;
    for (int k = 0; k < n; ++k) phi.segment<kModalFirst>(sub.rfe_index(l, k)).setZero();  // kept rows out: M_bb Φ_b below
    pattern.multiply(Mv, phi, Mphi);
    for (int k = 0; k < n; ++k) {
      const int at = sub.rfe_index(l, k);
      out.shapes.col(c).segment<kModalAxes>(kModalAxes * k) = phi.segment<kModalAxes>(at + kModalFirst);
      out.mass_shapes.col(c).segment<kModalAxes>(kModalAxes * k) = Mphi.segment<kModalAxes>(at + kModalFirst);
    }
  }
  if (derivatives > 0) add_modal_derivatives(sub, l, shared_pattern, Mv, all, pick, derivatives, parallel, out);
  out.q0 = VecX::Zero(N6);
  for (int k = 0; k < n; ++k) out.q0.segment<6>(6 * k) = all.q0.segment<6>(sub.rfe_index(l, k));
  return out;
}

namespace {
ModesResult modes_of(const Model& model, const VecX& qb, const VecX& vb, int count, int dense_limit,
                     const std::vector<int>& free, const Parallelism& parallel) {
  const int n = model.n(), nf = static_cast<int>(free.size()), N = model.flexible_dofs() + nf;
  if (std::set<int>(free.begin(), free.end()).size() != free.size())
    throw std::invalid_argument("a joint is freed twice");
  for (int j : free)
    if (j < 0 || j >= model.m())
      throw std::invalid_argument("no joint " + std::to_string(j + 1) + " to free (the model has " + std::to_string(model.m()) + ")");
  if (count < 1 || count > N)
    throw std::invalid_argument("mode count must be between 1 and 6n + free joints = " + std::to_string(N));
  ModesResult res;
  StaticOptions so;
  so.parallel = parallel;
  res.q0 = solve_static(model, qb, vb, TipLoads{}, so).q;  // (checks the sizes of qb and vb)
  Workspace ws(model, parallel);
  VecX v = VecX::Zero(model.dof());
  if (vb.size()) model.joint_coords(v) = vb;
  std::vector<int> cols(model.m(), -1);
  for (int i = 0; i < nf; ++i) cols[free[i]] = model.flexible_dofs() + i;
  if (nf > 0) {  // a free joint must be in equilibrium where the held ones are
    VecX F;
    generalised_forces(model, res.q0, v, VecX::Zero(model.dof()), ForceTerms{}, F, nullptr, &ws);
    const VecX tau = model.joint_coords(F);
    const double scale = std::max(1.0, tau.cwiseAbs().maxCoeff());
    for (int j : free)
      if (std::abs(tau[j]) > 1e-9 * scale)
        throw std::invalid_argument("joint " + std::to_string(j + 1) + " (" + model.joints[j].name + ") carries " +
                                    std::to_string(tau[j]) + (model.joints[j].type == JointType::Revolute ? " N m" : " N") + " in the held equilibrium: freed, it has no "
                                    "equilibrium to linearise about");
  }
  const auto shared_pattern = std::make_shared<const BorderedPattern>(model, cols);
  const BorderedPattern& pattern = *shared_pattern;
  const bool bordered = pattern.n_base() > 0;  // M is then not block diagonal
  std::vector<double> K, Mv;
  assemble_matrix(model, pattern, cols, res.q0, v, stiffness_terms(vb), K, &ws);
  const BlockMass bm = block_mass(model, res.q0);
  if (bordered) {
    MatrixTerms mt;
    mt.mass = 1.0;
    assemble_matrix(model, pattern, cols, res.q0, v, mt, Mv, &ws);
  }
  VecX lambda;
  if (N <= dense_limit) {
    MatX Md = MatX::Zero(N, N);
    if (bordered) Md = to_dense(pattern, Mv);
    else
      for (int k = 0; k < n; ++k) Md.block<6, 6>(6 * k, 6 * k) = bm.M[k];
    Eigen::GeneralizedSelfAdjointEigenSolver<MatX> es(to_dense(pattern, K), Md);
    if (es.info() != Eigen::Success) throw std::runtime_error("modal analysis: dense eigen-solver failed");
    lambda = es.eigenvalues().head(count);
    res.shapes = es.eigenvectors().leftCols(count);
  } else {
    res.dense = false;
    // Shift-invert Lanczos twice, at σ₁ and σ₁ − λ₁ (λ₁ the first elastic eigenvalue): the
    // factorisations of K − σM differ in their round-off (the stiff axial springs make K
    // ill-conditioned for many rfes), so the change of the eigenvalues estimates their error. (The
    // residual ‖Kφ − λMφ‖ does not: it is dominated by the round-off of Kφ itself and flags accurate
    // modes from n ≈ 80 on.) Held joints: M is block diagonal, the standard problem L⁻¹KL⁻ᵀ at
    // σ₁ = 0. Free joints: M is bordered, the generalised problem, and σ₁ just below 0, where the
    // rigid-body modes make K singular.
    const int ncv = std::min(N, std::max(2 * count + 1, count + 20));
    const int last = pattern.n_blocks() > 0 ? pattern.n_blocks() - 1 : n - 1;  // an rfe of a chain, if any
    const double scale = 1e-3 * std::abs(K[pattern.slot(6 * last, 6 * last)] / bm.M[last](0, 0));
    auto lanczos = [&](double sigma, VecX& lam, MatX& shapes) {
      if (bordered) {
        GeneralShiftInvertOp op(shared_pattern, K, Mv);
        MassProductOp bop(pattern, Mv);
        Spectra::SymGEigsShiftSolver<GeneralShiftInvertOp, MassProductOp, Spectra::GEigsMode::ShiftInvert> eigs(
            op, bop, count, ncv, sigma);
        ascending(eigs, lam, shapes);
        return;
      }
      ShiftInvertOp op(shared_pattern, K, bm);
      Spectra::SymEigsShiftSolver<ShiftInvertOp> eigs(op, count, ncv, sigma);
      MatX U;
      ascending(eigs, lam, U);
      shapes.resize(N, count);
      for (int i = 0; i < count; ++i)
        for (int k = 0; k < n; ++k)  // φ = L⁻ᵀ u
          shapes.col(i).segment<6>(6 * k) = bm.L[k].transpose().triangularView<Eigen::Upper>().solve(U.col(i).segment<6>(6 * k));
    };
    const double sigma = nf > 0 ? -1e-6 * scale : 0.0;
    lanczos(sigma, lambda, res.shapes);
    double first_elastic = lambda[0];
    if (nf > 0)
      for (int i = count - 1; i >= 0; --i)
        if (lambda[i] > 1e-9 * scale) first_elastic = lambda[i];
    VecX check;
    MatX check_shapes;
    lanczos(sigma - std::max(std::abs(first_elastic), 1e-12), check, check_shapes);
    res.uncertainty = ((check - lambda).cwiseAbs().array() / lambda.cwiseAbs().array().max(1e-300)).matrix();
  }
  if (res.uncertainty.size() == 0) res.uncertainty = VecX::Zero(count);
  // Rigid-body modes: ω² at the round-off of a zero eigenvalue of the stiffest coordinate.
  double stiffest = 0.0;
  for (int k = 0; k < n; ++k)
    for (int i = 0; i < 6; ++i) stiffest = std::max(stiffest, K[pattern.slot(6 * k + i, 6 * k + i)] / bm.M[k](i, i));
  separate_degenerate(lambda, res.shapes, res.uncertainty, bm);
  res.omega = lambda.cwiseMax(0.0).cwiseSqrt();
  for (int i = 0; i < count; ++i) {
    const bool rigid = nf > 0 && std::abs(lambda[i]) <= kRigidModeFraction * stiffest;
    if (rigid) {
      res.omega[i] = 0.0;
      res.uncertainty[i] = 0.0;
    }
    res.kind.push_back(rigid ? ModeKind::Rigid : classify(res.shapes.col(i), bm));
  }
  return res;
}

// The reduced model's modes: (Pᵀ K P, Pᵀ M P), dense (its size is the modes kept and the links kept
// whole), shapes lifted to every rfe coordinate.
ModesResult reduced_modes(const Model& model, const Reduction& red, const VecX& qb, const VecX& vb, int count,
                          const std::vector<int>& free, const Parallelism& parallel) {
  const int nf = static_cast<int>(free.size()), N = red.rfe() + nf;
  if (std::set<int>(free.begin(), free.end()).size() != free.size()) throw std::invalid_argument("a joint is freed twice");
  for (int j : free)
    if (j < 0 || j >= model.m())
      throw std::invalid_argument("no joint " + std::to_string(j + 1) + " to free (the model has " + std::to_string(model.m()) + ")");
  if (count < 1 || count > N)
    throw std::invalid_argument("mode count must be between 1 and the reduced model's " + std::to_string(N) +
                                " coordinates (kept modes, the rfe coordinates of links kept whole, free joints)");
  if (N > 3000) throw std::invalid_argument("modal analysis of a partly reduced model is dense: reduce the long links");
  ModesResult res;
  StaticOptions so;
  so.reduction = &red;
  so.parallel = parallel;
  res.q0 = solve_static(model, qb, vb, TipLoads{}, so).q;
  Workspace ws(model, parallel);
  VecX v = VecX::Zero(model.dof());
  if (vb.size()) model.joint_coords(v) = vb;
  std::vector<int> cols(model.m(), -1);
  for (int i = 0; i < nf; ++i) cols[free[i]] = model.flexible_dofs() + i;
  const BorderedPattern pattern(model, cols);
  std::vector<double> K, Mv;
  assemble_matrix(model, pattern, cols, res.q0, v, stiffness_terms(vb), K, &ws);
  MatrixTerms mt;
  mt.mass = 1.0;
  assemble_matrix(model, pattern, cols, res.q0, v, mt, Mv, &ws);
  const MatX Kr = MatX(red.reduce(pattern, K)), Mr = MatX(red.reduce(pattern, Mv));
  Eigen::GeneralizedSelfAdjointEigenSolver<MatX> es(Kr, Mr);
  if (es.info() != Eigen::Success) throw std::runtime_error("modal analysis: dense eigen-solver failed");
  const VecX lambda = es.eigenvalues().head(count);
  res.shapes.resize(model.flexible_dofs() + nf, count);
  for (int c = 0; c < count; ++c) {
    const VecX x = es.eigenvectors().col(c);
    red.lift(x.data(), res.shapes.col(c).data(), nf, false);
  }
  res.uncertainty = VecX::Zero(count);
  const BlockMass bm = block_mass(model, res.q0);
  double stiffest = 0.0;
  for (int i = 0; i < N; ++i) stiffest = std::max(stiffest, Kr(i, i) / Mr(i, i));
  separate_degenerate(lambda, res.shapes, res.uncertainty, bm);
  res.omega = lambda.cwiseMax(0.0).cwiseSqrt();
  for (int i = 0; i < count; ++i) {
    const bool rigid = nf > 0 && std::abs(lambda[i]) <= kRigidModeFraction * stiffest;
    if (rigid) res.omega[i] = 0.0;
    res.kind.push_back(rigid ? ModeKind::Rigid : classify(res.shapes.col(i), bm));
  }
  return res;
}
}  // namespace

}  // namespace rfem