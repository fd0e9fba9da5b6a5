#include "assemble.hpp"

#include <omp.h>
#include <sched.h>

#include <algorithm>

#include "rfe_kernels.hpp"
#include "sde_kernels.hpp"
#include "../core/check.hpp"

namespace rfem {

int Parallelism::team(int n) const {
  if (n < min_rfes) return 1;
  return max_threads();
}

int Parallelism::max_threads() const { return threads > 0 ? threads : omp_get_max_threads(); }

int available_cores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1, omp_get_num_procs());
}

std::string oversubscription(int processes, int threads_each, const std::string& who) {
  const int cores = available_cores();
  const long want = static_cast<long>(std::max(1, processes)) * std::max(1, threads_each);
  if (want <= cores) return {};
  return who + ": " + std::to_string(want) + " threads on " + std::to_string(cores) + " core" + (cores > 1 ? "s" : "") +
         ": they take turns (each waits for a core; " + std::to_string(cores) + " would run as fast)";
}

void Workspace::bind(const Model& model) {
  bound_rfes_ = model.n();
  bound_joints_ = model.m();
  bound_links_ = static_cast<int>(model.links.size());
  chunks(model);
}

void Workspace::check(const Model& model) const {
  if (bound_rfes_ < 0) return;
  RFEM_CHECK_ARGUMENT(bound_rfes_ == model.n() && bound_joints_ == model.m() && bound_links_ == static_cast<int>(model.links.size()),
                      "the workspace was built for a model of " + std::to_string(bound_rfes_) + " rfes and " +
                          std::to_string(bound_joints_) + " joints, not this one's " + std::to_string(model.n()) + " and " +
                          std::to_string(model.m()));
}

int Workspace::chunks(const Model& model) {
  chunk.clear();
  for (size_t l = 0; l < model.links.size(); ++l) {
    const int n = model.links[l].n();
    for (int k = 0; k < n; k += parallel.chunk) chunk.push_back({static_cast<int>(l), k, std::min(n, k + parallel.chunk)});
  }
  const int c = static_cast<int>(chunk.size());
  moments.assign(c, BaseMoments{});
  power.assign(c, 0.0);
  boundary.assign(c, Vec6::Zero());
  return c;
}

namespace {

// rfe_0's rotation (zero coordinates): R = I, ∂R/∂φ the generators.
const RfeRotation& clamp_rotation() {
  static const RfeRotation r = [] {
    DeformationTransform d;
    deformation_transform(Vec6::Zero(), d, false);
    return rfe_rotation(d);
  }();
  return r;
}

RfeRotation rotation_of(const Vec6& q) {
  DeformationTransform d;
  deformation_transform(q, d, false);
  return rfe_rotation(d);
}

Vec3 left_centre(const Discretisation& d, const Sde& e) {
  return e.left < 0 ? d.rfe0.centre : d.rfes[e.left].centre;
}

// Suffix sums over the tree: S[i] = the moments of every body node i moves — its own, the links on
// it (`link`: their rfes' moments) and its subtree's. Children come after their parents.
void suffix_moments(const Model& model, const BaseKinematics& bk, const std::vector<BaseMoments>& link,
                    std::vector<BaseMoments>& S) {
  const int N = static_cast<int>(model.nodes.size());
  S.assign(N, BaseMoments{});
  for (size_t l = 0; l < model.links.size(); ++l)
    if (model.links[l].parent >= 0) S[model.links[l].parent] += link[l];
  for (int i = N - 1; i >= 0; --i) {
    const Mat4 WH = bk.W[i] * model.nodes[i].H;
    BaseMoments b;
    b.Y = WH * bk.Wdd[i].transpose();
    b.G = WH * bk.W[i].transpose();
    b.s = WH.col(3);
    S[i] += b;
    if (model.nodes[i].parent >= 0) S[model.nodes[i].parent] += S[i];
  }
}

// A node's generalised force from the moments of everything it moves: rigid bodies through Y, the
// rfes through their wrench and the node's unit twist, gravity through s (linear in the moments).
double node_force(const Mat4& X, const BaseMoments& S, double g, bool inertia) {
  double eps = 0.0;
  if (inertia) eps = trace_prod(X, S.Y) + Vec3(X(2, 1), X(0, 2), X(1, 0)).dot(S.n) + X.topRightCorner<3, 1>().dot(S.f);
  return eps + g * (X * S.s)[2];
}

// Each link's rfe moments, summed over its chunks in chunk order.
std::vector<BaseMoments> link_moments(const Model& model, const Workspace& ws) {
  std::vector<BaseMoments> flex(model.links.size());
  for (size_t c = 0; c < ws.chunk.size(); ++c) flex[ws.chunk[c].link] += ws.moments[c];
  return flex;
}

}  // namespace

void generalised_forces(const Model& model, const VecX& q, const VecX& v, const VecX& a, const ForceTerms& terms,
                        VecX& F, double* dissipation, Workspace* wsp) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), model.dof(), "v");
  RFEM_CHECK_ARGUMENT_SIZE(a.size(), model.dof(), "a");
  Workspace local;
  Workspace& ws = wsp ? *wsp : local;
  ws.check(model);
  const double g = terms.gravity ? model.gravity : 0.0;
  F.resize(model.dof());
  F.tail(model.dof() - model.chain_dofs()).setZero();  // carrying rfes and joints: sums below
  if (!terms.velocity_products && ws.zero.size() != model.dof()) ws.zero = VecX::Zero(model.dof());
  const VecX& vi = terms.velocity_products ? v : ws.zero;  // velocity seen by the inertial terms
  BaseKinematics& bk = ws.bk;
  base_kinematics(model, q, vi, a, bk);
  const int nchunks = ws.chunks(model);
  // One pass per chunk: rfe k's pose and forces, then sde k (rfes k−1, k) with both rotations —
  // each rotation is evaluated once, except the one of the rfe before the chunk.
#pragma omp parallel for schedule(static) num_threads(ws.parallel.team(model.n()))
  for (int c = 0; c < nchunks; ++c) {
    const Workspace::Chunk ch = ws.chunk[c];
    const MountedLink& L = model.links[ch.link];
    const Discretisation& d = L.d;
    const LinkFrame& fr = bk.frame[ch.link];
    DeformationTransform dt;
    RfeRotation left = ch.begin > 0 ? rotation_of(rfe_coords(model, q, ch.link, ch.begin - 1)) : clamp_rotation();
    // Partial sums in locals, stored once per chunk: neighbouring chunks' slots share cache lines,
    // and a write per rfe from two threads makes the lines ping-pong (false sharing).
    BaseMoments mom;
    double power = 0.0;
    const Mat3 R0 = fr.B0.topLeftCorner<3, 3>();
    for (int k = ch.begin; k < ch.end; ++k) {
      if (L.carries(k)) continue;  // a node's body; its sdes come after the loop
      const Rfe& rfe = d.rfes[k];
      const int ik = model.rfe_index(ch.link, k);
      const Vec6 qk = q.segment<6>(ik);
      deformation_transform(qk, dt, false);
      const Vec3 p = fr.B0.topLeftCorner<3, 3>() * (rfe.centre + qk.head<3>()) + fr.B0.topRightCorner<3, 1>();
      Vec6 f = Vec6::Zero();
      if (terms.inertia) {
        Vec3 fi, ni;
        rfe_inertia(rfe, fr, dt, vi.segment<6>(ik), a.segment<6>(ik), p, f, fi, ni);
        mom.f += fi;
        mom.n += ni;
      }
      f.head<3>() += g * rfe.mass * R0.row(2).transpose();  // gravity on the mass centre
      mom.s += rfe.mass * Vec4(p[0], p[1], p[2], 1.0);
      F.segment<6>(ik) = f;
      const RfeRotation right = rfe_rotation(dt);
      if (terms.sde && !(k > 0 && L.carries(k - 1))) {
        const Sde& e = d.sdes[k];
        SdeResult r;
        sde_forces(e, left_centre(d, e), rfe.centre, d.damping_beta, left_coords(model, q, ch.link, k),
                   left_coords(model, v, ch.link, k), qk, v.segment<6>(ik), left, right, r);
        if (k == ch.begin) {
          if (k > 0) ws.boundary[c] = r.f.head<6>();  // rfe k−1 belongs to the previous chunk
        } else {
          F.segment<6>(model.rfe_index(ch.link, k - 1)) += r.f.head<6>();
        }
        F.segment<6>(ik) += r.f.tail<6>();
        power += r.P_d;
      }
      left = right;
    }
    ws.moments[c] = mom;
    ws.power[c] = power;
  }
  double Pd = 0.0;
  for (int c = 0; c < nchunks; ++c) {
    const Workspace::Chunk& ch = ws.chunk[c];
    if (ch.begin > 0 && terms.sde) F.segment<6>(model.rfe_index(ch.link, ch.begin - 1)) += ws.boundary[c];
    Pd += ws.power[c];
  }
  if (terms.sde)
    for (size_t l = 0; l < model.links.size(); ++l) {
      const int li = static_cast<int>(l);
      const Discretisation& d = model.links[l].d;
      for (int e : model.links[l].carrier_sdes) {
        SdeResult r;
        const int ie = model.rfe_index(li, e);
        sde_forces(d.sdes[e], left_centre(d, d.sdes[e]), d.rfes[e].centre, d.damping_beta, left_coords(model, q, li, e),
                   left_coords(model, v, li, e), q.segment<6>(ie), v.segment<6>(ie), r);
        if (e > 0) F.segment<6>(model.rfe_index(li, e - 1)) += r.f.head<6>();
        F.segment<6>(ie) += r.f.tail<6>();
        Pd += r.P_d;
      }
    }
  suffix_moments(model, bk, link_moments(model, ws), ws.node_moments);
  const std::vector<BaseMoments>& S = ws.node_moments;
  for (size_t i = 0; i < model.nodes.size(); ++i) {
    const Node& nd = model.nodes[i];
    F[nd.coord] += node_force(bk.Xi[i], S[i], g, terms.inertia);
    if (nd.joint < 0) continue;
    const JointDrive& dr = model.joints[nd.joint].drive;
    if (!dr.active()) continue;
    const double vj = v[nd.coord];
    if (terms.inertia) F[nd.coord] += dr.inertia * a[nd.coord];
    if (terms.sde) {
      F[nd.coord] += dr.dissipative_force(vj);
      Pd += dr.power(vj);
    }
  }
  if (dissipation) *dissipation = Pd;
}

void add_link_moments_to_nodes(const Model& model, const BaseKinematics& bk, int link, const BaseMoments& m,
                               const ForceTerms& terms, VecX& F) {
  RFEM_CHECK_INDEX(link, model.links.size(), "link");
  RFEM_CHECK_ARGUMENT_SIZE(F.size(), model.dof(), "F");
  RFEM_CHECK_ARGUMENT_SIZE(bk.Xi.size(), model.nodes.size(), "base kinematics");
  const int parent = model.links[link].parent;
  if (parent < 0) return;  // (a link on {0}: no node moves it)
  const double g = terms.gravity ? model.gravity : 0.0;
  for (int i : model.nodes[parent].path) F[model.nodes[i].coord] += node_force(bk.Xi[i], m, g, terms.inertia);
}

namespace {

using RowMat6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
using Block = Eigen::Map<RowMat6>;

// Adds sde e's 12×12 matrix A (coordinates [rfe e−1; rfe e], both in one chain, block b for rfe e)
// to `vals`: D_b, E_b and D_{b−1} (into *left instead when given: that rfe belongs to another chunk).
void scatter_sde(const BorderedPattern& p, int b, bool has_left, const Mat12& A, std::vector<double>& vals, Mat6* left) {
  Block(vals.data() + p.diag(b)) += A.bottomRightCorner<6, 6>();
  if (!has_left) return;
  Block(vals.data() + p.coupling(b)) += A.topRightCorner<6, 6>();
  if (left) *left = A.topLeftCorner<6, 6>();
  else Block(vals.data() + p.diag(b - 1)) += A.topLeftCorner<6, 6>();
}

// Adds a symmetric matrix over the coordinates of rfes `rfes` (each 6, unknown index = coordinate)
// to the pattern's upper triangle, entry by entry (an sde at a carrying rfe: chain blocks, their
// border columns and the border block alike).
template <int K>
void scatter_entries(const BorderedPattern& p, const int (&first)[K], const Eigen::Matrix<double, 6 * K, 6 * K>& A,
                     std::vector<double>& vals) {
  for (int X = 0; X < K; ++X)
    for (int Y = 0; Y < K; ++Y)
      for (int a = 0; a < 6; ++a)
        for (int b = 0; b < 6; ++b) {
          const int r = first[X] + a, c = first[Y] + b;
          if (r <= c) vals[p.slot(r, c)] += A(6 * X + a, 6 * Y + b);
        }
}

}  // namespace

void assemble_matrices(const Model& model, const BorderedPattern& pattern, const std::vector<int>& base_col,
                       const VecX& q, const VecX& v, const MatrixTerms& t, std::vector<double>& values,
                       const std::vector<SdeTarget>& extra, MatX* base_rows, Workspace* wsp) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), model.dof(), "v");
  RFEM_CHECK_ARGUMENT_SIZE(base_col.size(), model.m(), "base_col");
  {
    int unknown_joints = 0;
    for (int c : base_col) unknown_joints += c >= 0;
    RFEM_CHECK_ARGUMENT(pattern.size() == model.flexible_dofs() + unknown_joints,
                        "the pattern is not the one of this model and base_col");
  }
  Workspace local;
  Workspace& ws = wsp ? *wsp : local;
  ws.check(model);
  const int N = static_cast<int>(model.nodes.size()), m = model.m(), nb = pattern.n_base(),
            ne = static_cast<int>(extra.size()), n6 = model.chain_dofs();
  // Each chain block's values are zeroed by the chunk that writes them (in cache, on its thread);
  // the border block here.
  auto prepare = [&](std::vector<double>& x) {
    x.resize(pattern.nnz());
    std::fill(x.begin() + pattern.base(), x.end(), 0.0);
  };
  prepare(values);
  for (const auto& x : extra) prepare(*x.values);
  const Vec6 zero6 = Vec6::Zero();  // the rfes' accelerations: none in a matrix
  BaseKinematics& bk = ws.bk;
  base_kinematics(model, q, v, bk);
  const double g = t.gravity ? model.gravity : 0.0;
  const bool sdes = t.stiffness != 0.0 || t.damping != 0.0 || ne > 0;
  bool any_damping = t.damping != 0.0;
  for (const auto& x : extra) any_damping |= x.fc != 0.0;
  const bool second = sdes || t.inertial;  // the geometric stiffness and the centrifugal one need ∂²R
  const int nchunks = ws.chunks(model);
  ws.boundary_block.assign(static_cast<size_t>(nchunks) * (1 + ne), Mat6::Zero());
  if (base_rows) base_rows->setZero(m, pattern.size());
  // Each node's unknown index (−1: a held joint) and border column.
  std::vector<int> unknown(N), col(N);
  for (int i = 0; i < N; ++i) {
    const Node& nd = model.nodes[i];
    unknown[i] = nd.joint >= 0 ? base_col[nd.joint] : nd.coord;
    col[i] = unknown[i] >= 0 ? unknown[i] - n6 : -1;
  }
  std::vector<int> unknown_ancestors(model.links.size(), 0);  // a chain's border columns that are mass rows
  for (size_t l = 0; l < model.links.size(); ++l)
    for (int i : model.links[l].ancestors) unknown_ancestors[l] += col[i] >= 0;
#pragma omp parallel for schedule(static) num_threads(ws.parallel.team(model.n()))
  for (int c = 0; c < nchunks; ++c) {
    const Workspace::Chunk ch = ws.chunk[c];
    const MountedLink& L = model.links[ch.link];
    const Discretisation& d = L.d;
    const LinkFrame& fr = bk.frame[ch.link];
    const std::vector<int>& anc = L.ancestors;
    const bool damping = d.damping_beta != 0.0 && any_damping;
    RfePose pose;
    Mat6 Mkk;
    MatX border, gb;
    Mat4 G;
    Mat12 Ke, Ce, A;
    DeformationTransform left;  // the rfe before, for the sde between them
    BaseMoments mom;            // stored once at the chunk's end (see generalised_forces)
    if (sdes)
      deformation_transform(ch.begin > 0 ? rfe_coords(model, q, ch.link, ch.begin - 1) : Vec6::Zero().eval(), left, true);
    for (int k = ch.begin; k < ch.end; ++k) {
      if (L.carries(k)) continue;  // a node's body; its sdes come after the loop
      const Rfe& rfe = d.rfes[k];
      const int ik = model.rfe_index(ch.link, k), b = ik / Model::rfe_dofs;
      // D is assigned below, and so is the border wherever it is a mass row: zero E and, for a
      // chain with a carrying rfe at its end, the border (memory traffic dominates for large n).
      std::fill_n(values.data() + pattern.coupling(b), 36, 0.0);
      if (pattern.width(b) > unknown_ancestors[ch.link])
        std::fill_n(values.data() + pattern.border(b), 6 * pattern.width(b), 0.0);
      for (const auto& x : extra) std::fill_n(x.values->data() + pattern.diag(b), pattern.block_size(b), 0.0);
      rfe_pose(rfe, fr, q.segment<6>(ik), v.segment<6>(ik), zero6, pose, t.inertial, second);
      rfe_mass_blocks(rfe, pose, bk.Xi, anc, Mkk, border, G);
      mom.G += G;
      mom.s += pose.W * rfe.H.col(3);
      Mat6 blk = t.mass * Mkk;
      border *= t.mass;
      if (base_rows)
        for (size_t r = 0; r < anc.size(); ++r)
          if (model.nodes[anc[r]].joint >= 0) base_rows->row(model.nodes[anc[r]].joint).segment<6>(ik) = border.row(r);
      if (t.inertial) blk += t.stiffness * rfe_inertial_stiffness(rfe, pose, fr);
      if (g != 0.0) {
        gb.setZero(anc.size(), 6);
        rfe_gravity_border(rfe, pose, bk.Xi, anc, g, gb);
        border += t.stiffness * gb;
      }
      Block(values.data() + pattern.diag(b)) = blk;
      const long w = pattern.width(b);
      for (size_t r = 0; r < anc.size(); ++r) {
        if (col[anc[r]] < 0) continue;
        const long at = pattern.border(b) + pattern.border_pos(b, col[anc[r]]);
        for (int l = 0; l < 6; ++l) values[at + l * w] = border(r, l);
      }
      if (!sdes) continue;
      if (k > 0 && L.carries(k - 1)) {  // (that sde comes after the loop)
        left = pose.d;
        continue;
      }
      const Sde& e = d.sdes[k];
      sde_matrices(e, left_centre(d, e), rfe.centre, d.damping_beta, left_coords(model, q, ch.link, k), q.segment<6>(ik),
                   left, pose.d, Ke, damping ? &Ce : nullptr);
      const bool first = k == ch.begin && k > 0;  // its left rfe belongs to the previous chunk
      const size_t bslot = static_cast<size_t>(c) * (1 + ne);
      A = t.stiffness * Ke;
      if (damping) A += t.damping * Ce;
      scatter_sde(pattern, b, k > 0, A, values, first ? &ws.boundary_block[bslot] : nullptr);
      for (int i = 0; i < ne; ++i) {
        A = extra[i].fk * Ke;
        if (damping) A += extra[i].fc * Ce;
        scatter_sde(pattern, b, k > 0, A, *extra[i].values, first ? &ws.boundary_block[bslot + 1 + i] : nullptr);
      }
      left = pose.d;
    }
    ws.moments[c] = mom;
  }
  if (sdes)
    for (int c = 0; c < nchunks; ++c) {
      const Workspace::Chunk& ch = ws.chunk[c];
      if (ch.begin == 0 || model.links[ch.link].carries(ch.begin - 1)) continue;
      const int b = model.rfe_index(ch.link, ch.begin - 1) / Model::rfe_dofs;
      const size_t bslot = static_cast<size_t>(c) * (1 + ne);
      Block(values.data() + pattern.diag(b)) += ws.boundary_block[bslot];
      for (int i = 0; i < ne; ++i) Block(extra[i].values->data() + pattern.diag(b)) += ws.boundary_block[bslot + 1 + i];
    }
  // Carrying rfes: the sdes at their ends, and (on request) their own centrifugal stiffness.
  for (size_t l = 0; l < model.links.size(); ++l) {
    const int li = static_cast<int>(l);
    const MountedLink& L = model.links[l];
    const Discretisation& d = L.d;
    const bool damping = d.damping_beta != 0.0 && any_damping;
    if (sdes)
      for (int e : L.carrier_sdes) {
        Mat12 Ke, Ce, A;
        sde_matrices(d.sdes[e], left_centre(d, d.sdes[e]), d.rfes[e].centre, d.damping_beta, left_coords(model, q, li, e),
                     rfe_coords(model, q, li, e), Ke, damping ? &Ce : nullptr);
        if (e == 0) {  // rfe_0 is rigid with {r}: only rfe e's block
          const int first[1] = {model.rfe_index(li, e)};
          Mat6 B = t.stiffness * Ke.bottomRightCorner<6, 6>();
          if (damping) B += t.damping * Ce.bottomRightCorner<6, 6>();
          scatter_entries<1>(pattern, first, B, values);
          for (const auto& x : extra) {
            B = x.fk * Ke.bottomRightCorner<6, 6>();
            if (damping) B += x.fc * Ce.bottomRightCorner<6, 6>();
            scatter_entries<1>(pattern, first, B, *x.values);
          }
          continue;
        }
        const int first[2] = {model.rfe_index(li, e - 1), model.rfe_index(li, e)};
        A = t.stiffness * Ke;
        if (damping) A += t.damping * Ce;
        scatter_entries<2>(pattern, first, A, values);
        for (const auto& x : extra) {
          A = x.fk * Ke;
          if (damping) A += x.fc * Ce;
          scatter_entries<2>(pattern, first, A, *x.values);
        }
      }
    if (t.inertial && t.stiffness != 0.0)
      for (int k = 0; k < L.n(); ++k) {
        if (!L.carries(k)) continue;
        RfePose pose;
        const int ik = model.rfe_index(li, k);
        rfe_pose(d.rfes[k], bk.frame[l], q.segment<6>(ik), v.segment<6>(ik), zero6, pose, true, true);
        const int first[1] = {ik};
        const Mat6 B = t.stiffness * rfe_inertial_stiffness(d.rfes[k], pose, bk.frame[l]);
        scatter_entries<1>(pattern, first, B, values);
      }
  }
  suffix_moments(model, bk, link_moments(model, ws), ws.node_moments);
  const std::vector<BaseMoments>& S = ws.node_moments;
  for (int j = 0; j < N; ++j)
    for (int l = 0; l < N; ++l) {
      if (unknown[l] < 0) continue;  // columns are unknowns only
      const int lo = std::min(j, l), hi = std::max(j, l);
      if (!model.ancestor(lo, hi)) continue;  // no body moves with both
      const int jj = model.nodes[j].joint;
      double mass = t.mass * trace_prod(bk.Xi[j] * S[hi].G, bk.Xi[l].transpose());
      if (j == l && jj >= 0) mass += t.mass * model.joints[jj].drive.inertia;
      if (base_rows && jj >= 0) (*base_rows)(jj, unknown[l]) = mass;
      if (col[j] < 0 || l < j) continue;
      double val = mass;
      if (g != 0.0) val += t.stiffness * g * (bk.Xi[lo] * bk.Xi[hi] * S[hi].s)[2];
      if (j == l && jj >= 0 && t.damping != 0.0) val += t.damping * model.joints[jj].drive.damping_derivative(v[model.nodes[j].coord]);
      values[pattern.base() + static_cast<long>(std::min(col[j], col[l])) * nb + std::max(col[j], col[l])] += val;
    }
}

void assemble_matrix(const Model& model, const BorderedPattern& pattern, const std::vector<int>& base_col,
                     const VecX& q, const VecX& v, const MatrixTerms& t, std::vector<double>& values, Workspace* ws) {
  assemble_matrices(model, pattern, base_col, q, v, t, values, {}, nullptr, ws);
}

Energies energies(const Model& model, const VecX& q, const VecX& v, Workspace* wsp) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), model.dof(), "v");
  Workspace local;
  Workspace& ws = wsp ? *wsp : local;
  ws.check(model);
  Energies E;
  BaseKinematics& bk = ws.bk;
  base_kinematics(model, q, v, bk);
  for (size_t i = 0; i < model.nodes.size(); ++i) {
    const Node& nd = model.nodes[i];
    E.kinetic += 0.5 * trace_prod(bk.Wd[i] * nd.H, bk.Wd[i].transpose());
    E.gravity += model.gravity * (bk.W[i] * nd.H.col(3))[2];
    if (nd.joint < 0) continue;
    const double vi = v[nd.coord];
    E.kinetic += model.joints[nd.joint].drive.kinetic_energy(vi);
    E.dissipation_rate += model.joints[nd.joint].drive.power(vi);
  }
  const int nchunks = ws.chunks(model);
  std::vector<Eigen::Vector4d> part(nchunks, Eigen::Vector4d::Zero());  // T, V_g, V_e, P_d per chunk
#pragma omp parallel for schedule(static) num_threads(ws.parallel.team(model.n()))
  for (int c = 0; c < nchunks; ++c) {
    const Workspace::Chunk ch = ws.chunk[c];
    const MountedLink& L = model.links[ch.link];
    const Discretisation& d = L.d;
    RfePose pose;
    Eigen::Vector4d chunk_sum = Eigen::Vector4d::Zero();  // stored once (see generalised_forces)
    for (int k = ch.begin; k < ch.end; ++k) {
      if (L.carries(k)) continue;
      const int ik = model.rfe_index(ch.link, k);
      rfe_pose(d.rfes[k], bk.frame[ch.link], q.segment<6>(ik), v.segment<6>(ik), Vec6::Zero(), pose, false);
      SdeResult r;
      if (!(k > 0 && L.carries(k - 1))) {
        const Sde& s = d.sdes[k];
        sde_forces(s, left_centre(d, s), d.rfes[k].centre, d.damping_beta, left_coords(model, q, ch.link, k),
                   left_coords(model, v, ch.link, k), q.segment<6>(ik), v.segment<6>(ik), r);
      }
      chunk_sum += Eigen::Vector4d(rfe_kinetic_energy(d.rfes[k], pose, bk.frame[ch.link], v.segment<6>(ik)),
                                   model.gravity * (pose.W * d.rfes[k].H.col(3))[2], r.V, r.P_d);
    }
    part[c] = chunk_sum;
  }
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (const auto& p : part) sum += p;  // chunk order: the same bits for any thread count
  E.kinetic += sum[0];
  E.gravity += sum[1];
  E.elastic = sum[2];
  E.dissipation_rate += sum[3];
  for (size_t l = 0; l < model.links.size(); ++l) {  // sdes at carrying rfes
    const int li = static_cast<int>(l);
    const Discretisation& d = model.links[l].d;
    for (int e : model.links[l].carrier_sdes) {
      SdeResult r;
      sde_forces(d.sdes[e], left_centre(d, d.sdes[e]), d.rfes[e].centre, d.damping_beta, left_coords(model, q, li, e),
                 left_coords(model, v, li, e), rfe_coords(model, q, li, e), rfe_coords(model, v, li, e), r);
      E.elastic += r.V;
      E.dissipation_rate += r.P_d;
    }
  }
  return E;
}

}  // namespace rfem
