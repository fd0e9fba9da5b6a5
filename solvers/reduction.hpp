#pragma once
// Modal reduction of flexible links (docs/formulation.md §9). A link with `modes = m` keeps, instead
// of its rfes' 3n rotations (φ1, φ2, φ3), m modal coordinates η:
//   φ_l = φ_l0 + Φ_l η_l,
// Φ_l the rotation rows of its first m modes clamped in {r} (every joint held at the initial values,
// every other link rigid; its sections and payloads as given; M-normalised) whose rotations add a
// direction, φ_l0 those of the static equilibrium they are taken about. Each rfe's displacements
// x1, x2, x3 stay unknowns: a bent link's rfes must be free to follow their rotations rigidly
// (shorten along the axis, move across it by the sine of the angle), which a linear combination of
// displacement modes cannot do: the stiff shear and axial sdes then resist the difference at second
// and third order, and a spinning link locks (Kane's spin-up 4.3 % low at 6 rad/s with 8 to 250 of
// 300 modes when the modes spanned x2, x3 too). The equations are projected (Galerkin):
// r_η = Φ_lᵀ r_l, so the full nonlinear kinematics, the base coupling and centrifugal effects stay;
// only the rotations the link can take are limited, and with m = 3n it is the full model. Over a
// coordinate vector of 6n rfe coordinates followed by k joint coordinates,
//   x_full = P x (+ q0 for positions),   P = blockdiag(links kept whole: I; reduced: Φ_l; joints: I).
// Reduced unknowns are ordered: the rfe coordinates kept (links kept whole, reduced links'
// displacements; model order), each reduced link's η, then the joints. Immutable once built; shared
// by the equations, statics and modes.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "../assembly/pattern.hpp"
#include "../assembly/workspace.hpp"
#include "../core/model.hpp"

namespace rfem {

using SparseMat = Eigen::SparseMatrix<double>;

/// Some link of the model keeps modes (d.modes > 0) instead of its rfes' rotations.
bool has_reduced_link(const Model& model);

class Reduction {
 public:
  struct Link {
    int link = 0;           ///< the model's link
    int first = 0;          ///< its first column among the reduced rfe unknowns
    std::vector<int> rfe;   ///< first full coordinate of each of its rfes
    MatX phi;               ///< 3n × (m + its derivatives), rows rfe by rfe (k = 0 … n − 1), axes φ1 … φ3
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> phi_rows;  ///< Φ_l row-major (lift, project)
    MatX mass_phi;          ///< M_bb Φ_l over the same coordinates
    Eigen::LLT<MatX> gram;  ///< of Φ_lᵀ M_bb Φ_l: the M-orthogonal projection back, G η = (M Φ)ᵀ (q − q0)
    VecX q0;                ///< 6n, rfe by rfe (x1 unused)
    VecX omega;             ///< the m clamped frequencies [rad/s]
    int modes = 0;          ///< m: the columns of Φ_l after them are modal derivatives
    std::vector<std::pair<int, int>> pairs;  ///< the modes (from 1) of each derivative column
  };

  /// The reduction of every link with d.modes > 0, its modes taken at joint values qb on the
  /// threads `parallel` allows (the caller's choice holds here too). Throws std::invalid_argument
  /// naming the link for modes larger than 6n, or a cut through a pair of equal frequencies.
  Reduction(const Model& model, const VecX& qb, const Parallelism& parallel = {});
  /// Null if no link of the model is reduced (has_reduced_link).
  static std::shared_ptr<const Reduction> of(const Model& model, const VecX& qb, const Parallelism& parallel = {});

  int full_rfe() const { return full_rfe_; }  ///< 6n
  int rfe() const { return rfe_; }            ///< reduced rfe unknowns
  int kept() const { return static_cast<int>(kept_.size()); }  ///< of them, the rfe coordinates kept (they come first)
  const std::vector<Link>& links() const { return links_; }
  /// P over 6n + k coordinates (k joints appended), as a sparse matrix.
  SparseMat projector(int k) const;
  /// x_full (6n + k) = P x (+ q0 if `positions`), x of rfe() + k values; on `team` threads
  /// (rfe by rfe: the same bits for any team).
  void lift(const double* x, double* x_full, int k, bool positions, int team = 1) const;
  /// lift of positions q (with q0), rates v and accelerations a (a may be null) in one pass over Φ.
  void lift_state(const double* q, const double* v, const double* a, double* qf, double* vf, double* af, int k,
                  int team = 1) const;
  /// lift_state of an ESDIRK stage's Q = Qk + (hγ)² A, V = Vk + hγ A from Qk, Vk lifted once (qk, vk:
  /// lift_state's qf, vf of them) and A alone: one pass over Φ instead of three. The kept and joint
  /// coordinates are Q's, V's, A's; the reduced links' modal ones equal lift_state's to round-off.
  void lift_stage(const double* Q, const double* V, const double* A, const double* qk, const double* vk, double hg,
                  double* qf, double* vf, double* af, int k, int team = 1) const;
  /// r = Pᵀ r_full; on `team` threads (Φᵀ r summed over fixed blocks of rfes in order: the same
  /// bits for any team).
  void project(const double* r_full, double* r, int k, int team = 1) const;
  /// The reduced coordinates nearest (M-orthogonal for reduced links) to full ones.
  void restrict(const double* x_full, double* x, int k, bool positions) const;
  /// Pᵀ S P for the symmetric matrix with upper triangle `values` on a pattern of 6n + k unknowns
  /// (once; a Projection does it repeatedly).
  SparseMat reduce(const BorderedPattern& pattern, const std::vector<double>& values) const;
  /// Names of the reduced rfe unknowns: the kept ones' (from the full names), then LINK/eta1 …
  /// and each derivative's LINK/xi_i_j.
  std::vector<std::string> names(const Model& model, const std::vector<std::string>& full_names) const;
  /// The reduced unknowns that are modal derivatives, ascending. They are quasi-static corrections
  /// (second-order shapes, docs/formulation.md §9): the integrators leave them out of the error
  /// estimate (their Newton convergence is still tested), so the steps follow the modes.
  const std::vector<int>& quasi_static() const { return quasi_static_; }

 private:
  template <class Kept, class Modal>
  void for_lifted(const double* const* x, int cols, int team, Kept&& kept, Modal&& modal) const;
  int full_rfe_ = 0, rfe_ = 0;
  std::vector<int> kept_;  ///< full index of each kept rfe coordinate (they come first)
  std::vector<Link> links_;
  std::vector<int> quasi_static_;
};

/// Pᵀ S P for matrices S on one pattern, again and again. Its layout is fixed once: S's compressed
/// columns (both triangles) with each value's slot in the pattern, and the reduced matrix's pattern
/// with the source of each entry. Each call then gathers S's values, forms W_l = S Φ_l (S sparse,
/// Φ_l dense over link l's modal rows: nnz · m) and reads every reduced entry off S (kept × kept),
/// W_l (kept × η_l) or Φ_lᵀ W_l' (η_l × η_l'), in place — a generic sparse product with Φ's dense
/// columns cost 3× more per step (docs/performance.md, "Reduced links").
class Projection {
 public:
  Projection(const Reduction& reduction, const BorderedPattern& pattern);
  /// Pᵀ S P for the upper triangle `values` (pattern.nnz()); valid until the next call. On `team`
  /// threads: W_l row by row, Φ_lᵀ W_l' in fixed column blocks (the same bits for any team).
  const SparseMat& reduce(const std::vector<double>& values, int team = 1);

 private:
  struct Source {      // where a reduced entry's value comes from
    enum Kind { S, W, G } kind = S;
    int block = 0;     // W: the link l of W_l; G: the pair of G_ (l·links + l')
    int a = 0, c = 0;  // S: S_'s value a; W, G: (row a, column c) of the block
  };
  const Reduction* red_ = nullptr;
  SparseMat S_, R_;
  std::vector<long> slot_;      // S_'s value k is values[slot_[k]]
  std::vector<Source> source_;  // R_'s value k
  using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  std::vector<int> link_of_;    // per full coordinate: its reduced link (−1: kept)
  std::vector<int> phi_row_;    // per full coordinate of a reduced link: its row of Φ_l
  struct Modal {     // an entry of S in a reduced link's modal row
    long value;        // its index in S_'s values
    int link, phi_row; // the link and the row of Φ_l
  };
  std::vector<long> modal_ptr_;   // column i's modal entries: lat_[modal_ptr_[i] … modal_ptr_[i + 1])
  std::vector<Modal> lat_;
  std::vector<char> twin_;      // column i's modal entries in the same rows of Φ as column i + 1's
  template <int R>
  void w_rows(long i, long skip, long count, const double* v);
  std::vector<RowMat> W_;       // S Φ_l over every full row (row i from S's column i: S is symmetric; rows by w_row_)
  std::vector<int> w_row_;      // per full coordinate: its row of W_l (kept ones first, then each link's modal rows)
  std::vector<int> modal_first_;  // per link: W's row of its first modal coordinate
  std::vector<MatX> G_;         // Φ_lᵀ W_l' per link pair (l·links + l')
};

/// Factor of a reduced (sparse, symmetric) matrix S = [T B; Bᵀ D] split after its `kept` leading
/// unknowns: T over the rfe coordinates kept (sparse: a reduced link's displacements, the links
/// kept whole), B and D dense over the modal coordinates and joints that border it. T by a sparse
/// LDLᵀ (its ordering analysed once per pattern), then the Schur complement D − Bᵀ T⁻¹ B by a dense
/// LDLᵀ; a solve is one sparse solve with T and two products with the border on the team (a sparse
/// LDLᵀ of the whole S filled T's rows with the border and solved it serially: 13 solves a step,
/// the second thread waiting; docs/performance.md, "Reduced links"). Each product's entries are
/// sums in a fixed order: the same bits for any team. `definite`: false unless positive definite
/// (a Newton matrix); otherwise an indefinite matrix is factorised as CHOLMOD's LDLᵀ does for the
/// full statics (a spinning link's stiffness before the centrifugal tension has built up).
class ReducedFactor {
 public:
  bool factorize(const SparseMat& S, int kept, bool definite = true, int team = 1);
  void solve(VecX& b, int team = 1) const;

 private:
  using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::SimplicialLDLT<SparseMat, Eigen::Lower, Eigen::AMDOrdering<int>> t_;
  SparseMat T_;       // S's kept block (its pattern kept between calls)
  RowMat Bt_, Yt_;    // Bᵀ and (T⁻¹ B)ᵀ, border × kept
  MatX schur_;        // D − Bᵀ T⁻¹ B
  Eigen::LDLT<MatX> s_;
  long nnz_ = -1;
  int size_ = -1, kept_ = -1;
};

}  // namespace rfem
