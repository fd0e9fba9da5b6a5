#pragma once
// Modal reduction of flexible links (docs/formulation.md §9). A link with `modes = m` keeps, instead
// of its rfes' 5n lateral and rotational coordinates (x2, x3, φ1, φ2, φ3), m modal coordinates η:
//   q_l = q_l0 + Φ_l η_l,
// Φ_l its first m modes clamped in {r} (every joint held at the initial values, every other link
// rigid; its sections and payloads as given; M-normalised), q_l0 the static equilibrium they are
// taken about; their x1 rows are left out. Each rfe's axial coordinate x1 stays an unknown: a bent
// link's rfes must be free to draw closer along its axis, or the stiff axial sdes resist every
// deflection at second order (membrane locking: Kane's spin-up then deflects 0.12 m instead of
// 0.57 m), and with them the centrifugal tension that stiffens a rotating link stays. (Modes taken
// with x1 held instead are wrong where a section's centroid is offset: bending then moves x1.) The equations are projected (Galerkin): r_η = Φ_lᵀ r_l, so the full nonlinear
// kinematics, the base coupling and centrifugal effects stay; only the shapes the link can take are
// limited. Over a coordinate vector of 6n rfe coordinates followed by k joint coordinates,
//   x_full = P x (+ q0 for positions),   P = blockdiag(links kept whole: I; reduced: Φ_l; joints: I).
// Reduced unknowns are ordered: the rfe coordinates kept (links kept whole, reduced links' x1; model
// order), each reduced link's η, then the joints. Immutable once built; shared by the equations, statics and modes.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "rfem/assembly/pattern.hpp"
#include "rfem/core/model.hpp"

namespace rfem {

using SparseMat = Eigen::SparseMatrix<double>;

class Reduction {
 public:
  struct Link {
    int link = 0;           ///< the model's link
    int first = 0;          ///< its first column among the reduced rfe unknowns
    std::vector<int> rfe;   ///< first full coordinate of each of its rfes
    MatX phi;               ///< 5n × m, rows rfe by rfe (k = 0 … n − 1), axes x2 … φ3
    MatX mass_phi;          ///< M_bb Φ_l over the same coordinates
    Eigen::LLT<MatX> gram;  ///< of Φ_lᵀ M_bb Φ_l: the M-orthogonal projection back, G η = (M Φ)ᵀ (q − q0)
    VecX q0;                ///< 6n, rfe by rfe (x1 unused)
    VecX omega;             ///< the m clamped frequencies [rad/s]
  };

  /// The reduction of every link with d.modes > 0, its modes taken at joint values qb. Throws
  /// std::invalid_argument naming the link for modes larger than 6n, or a cut through a pair of
  /// equal frequencies.
  Reduction(const Model& model, const VecX& qb);
  /// Null if no link of the model is reduced.
  static std::shared_ptr<const Reduction> of(const Model& model, const VecX& qb);

  int full_rfe() const { return full_rfe_; }  ///< 6n
  int rfe() const { return rfe_; }            ///< reduced rfe unknowns
  const std::vector<Link>& links() const { return links_; }
  /// P over 6n + k coordinates (k joints appended), as a sparse matrix.
  SparseMat projector(int k) const;
  /// x_full (6n + k) = P x (+ q0 if `positions`), x of rfe() + k values.
  void lift(const double* x, double* x_full, int k, bool positions) const;
  /// r = Pᵀ r_full.
  void project(const double* r_full, double* r, int k) const;
  /// The reduced coordinates nearest (M-orthogonal for reduced links) to full ones.
  void restrict(const double* x_full, double* x, int k, bool positions) const;
  /// Pᵀ S P for the symmetric matrix with upper triangle `values` on a pattern of 6n + k unknowns
  /// (once; a Projection does it repeatedly).
  SparseMat reduce(const BorderedPattern& pattern, const std::vector<double>& values) const;
  /// Names of the reduced rfe unknowns: the kept ones' (from the full names), then LINK/eta1 ….
  std::vector<std::string> names(const Model& model, const std::vector<std::string>& full_names) const;

 private:
  int full_rfe_ = 0, rfe_ = 0;
  std::vector<int> kept_;  ///< full index of each kept rfe coordinate (they come first)
  std::vector<Link> links_;
};

/// Pᵀ S P for matrices S on one pattern, again and again. Its layout is fixed once: S's compressed
/// columns (both triangles) with each value's slot in the pattern, and the reduced matrix's pattern
/// with the source of each entry. Each call then gathers S's values, forms W_l = S Φ_l (S sparse,
/// Φ_l dense over link l's lateral rows: nnz · m) and reads every reduced entry off S (kept × kept),
/// W_l (kept × η_l) or Φ_lᵀ W_l' (η_l × η_l'), in place — a generic sparse product with Φ's dense
/// columns cost 3× more per step (docs/performance.md, "Reduced links").
class Projection {
 public:
  Projection(const Reduction& reduction, const BorderedPattern& pattern);
  /// Pᵀ S P for the upper triangle `values` (pattern.nnz()); valid until the next call.
  const SparseMat& reduce(const std::vector<double>& values);

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
  std::vector<RowMat> W_;       // S Φ_l over every full row (rows: S's columns are added row-wise)
  RowMat wb_;                   // W_l' at link l's lateral rows
  std::vector<MatX> G_;         // Φ_lᵀ W_l' per link pair (l·links + l')
};

/// LDLᵀ factor of a reduced (sparse, symmetric) matrix, its ordering analysed once per pattern.
/// `definite`: false unless positive definite (a Newton matrix); otherwise an indefinite matrix
/// is factorised as CHOLMOD's LDLᵀ does for the full statics (a spinning link's stiffness before
/// the centrifugal tension has built up).
class ReducedFactor {
 public:
  bool factorize(const SparseMat& S, bool definite = true);
  void solve(VecX& b) const;

 private:
  Eigen::SimplicialLDLT<SparseMat, Eigen::Lower, Eigen::AMDOrdering<int>> llt_;
  long nnz_ = -1;
  int size_ = -1;
};

}  // namespace rfem
