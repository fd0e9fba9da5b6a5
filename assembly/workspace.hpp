#pragma once
// What the assembly kernels may use besides their arguments: a thread policy and scratch, owned
// by the caller (one Workspace per calling thread; the kernels keep no state of their own — the
// Model/Data split of Pinocchio). Per-rfe loops run over fixed chunks of rfes whose partial sums
// are combined in chunk order, so results are the same bits for any number of threads.
#include <algorithm>
#include <string>
#include <vector>

#include "../core/kinematics.hpp"

namespace rfem {

/// The cores this process may run on (its CPU affinity: a container's or a batch job's share, not
/// the machine's).
int available_cores();
/// A warning if `processes` × `threads_each` threads would share fewer cores ("" if they fit), in
/// the words of `who` ("--threads 4", "--jobs 4", "4 MPI ranks on this node"): threads that wait for
/// a core at every barrier run slower than fewer threads would.
std::string oversubscription(int processes, int threads_each, const std::string& who);

/// How many threads the per-rfe loops use.
struct Parallelism {
  int threads = 0;     ///< team size (0: max_threads(), OpenMP's default: OMP_NUM_THREADS or the cores)
  int min_rfes = 256;  ///< fewer rfes run on one thread: a parallel region costs more than it saves
  /// rfes per chunk: the unit of work and of partial sums. Results depend on it (summation
  /// order), never on the thread count; tests make it small to exercise the chunk boundaries.
  int chunk = 64;
  /// Team size for a loop over n rfes.
  int team(int n) const;
  /// The largest team: `threads`, or OpenMP's default if 0 (read, never set: the caller's
  /// omp_set_num_threads is the caller's business).
  int max_threads() const;
};

/// Σ over bodies of what the base rows need: Y = W H Ẅᵀ (rigid links), G = W H Wᵀ, s = W H e₄,
/// and the rfes' inertial wrench about the origin of {0} (force f, moment n).
struct BaseMoments {
  Mat4 Y = Mat4::Zero(), G = Mat4::Zero();
  Vec4 s = Vec4::Zero();
  Vec3 f = Vec3::Zero(), n = Vec3::Zero();
  BaseMoments& operator+=(const BaseMoments& o) {
    Y += o.Y;
    G += o.G;
    s += o.s;
    f += o.f;
    n += o.n;
    return *this;
  }
};

struct Workspace {
  /// Unbound: adapts to whatever model it is given (tests, one-off calls).
  Workspace() = default;
  explicit Workspace(const Parallelism& p) : parallel(p) {}
  /// Bound to `model` (its chunks cut once): every kernel it is passed to checks that it gets that
  /// model's shape — the hot paths (the equations, statics, the rigid torques) use one of these.
  explicit Workspace(const Model& model, const Parallelism& p = {}) : parallel(p) { bind(model); }
  void bind(const Model& model);
  /// std::invalid_argument unless unbound or bound to a model of this shape (rfes, joints, links).
  void check(const Model& model) const;
  Parallelism parallel;
  BaseKinematics bk;
  /// A chunk: rfes begin … end − 1 of one link (chunks never span two links).
  struct Chunk {
    int link = 0, begin = 0, end = 0;
  };
  std::vector<Chunk> chunk;
  std::vector<BaseMoments> moments;  ///< per chunk
  std::vector<double> power;         ///< per chunk: sde dissipation
  std::vector<Vec6> boundary;        ///< per chunk: its first sde's force on the previous chunk's last rfe
  std::vector<Mat6> boundary_block;  ///< per chunk (and target): the same sde's block on that rfe
  VecX zero;                         ///< zeros of the model's size (velocity products off: tests only)
  std::vector<BaseMoments> node_moments;  ///< per node: its subtree's (suffix sums over the tree)
  /// Cuts every link of the model into chunks, sizes the chunk arrays (cleared) and returns the
  /// number of chunks.
  int chunks(const Model& model);

 private:
  int bound_rfes_ = -1, bound_joints_ = -1, bound_links_ = -1;  // −1: unbound
};

}  // namespace rfem
