#include "reduction.hpp"

#include <algorithm>
#include <stdexcept>

#include "modes.hpp"
#include "team_parts.hpp"

namespace rfem {

Reduction::Reduction(const Model& model, const VecX& qb, const Parallelism& parallel) : full_rfe_(model.flexible_dofs()) {
  std::vector<char> reduced(full_rfe_, 0);
  for (size_t l = 0; l < model.links.size(); ++l) {
    const MountedLink& L = model.links[l];
    if (L.d.modes <= 0) continue;
    LinkModes lm = link_modes(model, static_cast<int>(l), qb, L.d.modes, L.d.derivatives, parallel);
    Link r;
    r.link = static_cast<int>(l);
    for (int k = 0; k < L.n(); ++k) {
      r.rfe.push_back(model.rfe_index(static_cast<int>(l), k));
      for (int a = kModalFirst; a < Model::rfe_dofs; ++a) reduced[r.rfe.back() + a] = 1;  // x1, x2, x3 stay unknowns
    }
    r.phi = std::move(lm.shapes);
    r.phi_rows = r.phi;
    r.mass_phi = std::move(lm.mass_shapes);
    r.gram.compute(r.phi.transpose() * r.mass_phi);
    if (r.gram.info() != Eigen::Success)
      throw std::invalid_argument("link " + L.name + ": its " + std::to_string(L.d.modes) +
                                  " modes are not independent in their rotations: keep fewer");
    r.q0 = std::move(lm.q0);
    r.omega = std::move(lm.omega);
    r.modes = L.d.modes;
    r.pairs = std::move(lm.pairs);
    links_.push_back(std::move(r));
  }
  for (int i = 0; i < full_rfe_; ++i)
    if (!reduced[i]) kept_.push_back(i);
  rfe_ = static_cast<int>(kept_.size());
  for (Link& r : links_) {
    r.first = rfe_;
    for (int c = r.modes; c < r.phi.cols(); ++c) quasi_static_.push_back(rfe_ + c);
    rfe_ += static_cast<int>(r.phi.cols());
  }
}

bool has_reduced_link(const Model& model) {
  return std::any_of(model.links.begin(), model.links.end(), [](const MountedLink& l) { return l.d.modes > 0; });
}

std::shared_ptr<const Reduction> Reduction::of(const Model& model, const VecX& qb, const Parallelism& parallel) {
  return has_reduced_link(model) ? std::make_shared<const Reduction>(model, qb, parallel) : nullptr;
}

SparseMat Reduction::projector(int k) const {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < static_cast<int>(kept_.size()); ++i) t.emplace_back(kept_[i], i, 1.0);
  for (const Link& r : links_)
    for (size_t e = 0; e < r.rfe.size(); ++e)
      for (int a = 0; a < kModalAxes; ++a)
        for (int c = 0; c < r.phi.cols(); ++c) t.emplace_back(r.rfe[e] + kModalFirst + a, r.first + c, r.phi(kModalAxes * e + a, c));
  for (int j = 0; j < k; ++j) t.emplace_back(full_rfe_ + j, rfe_ + j, 1.0);
  SparseMat P(full_rfe_ + k, rfe_ + k);
  P.setFromTriplets(t.begin(), t.end());
  return P;
}

namespace {
// Φ_l's rows of rfes [b, e) times `cols` (1–3) vectors η (reduced, at the link's first column) into
// out (5(e − b) rows per vector, one after the other): each entry a dot product of a row of Φ_l
// (row-major, the copy the projections read: one copy of Φ stays in the caches) with η (the same
// bits for any part and team).
void phi_times(const Reduction::Link& r, long b, long e, const double* const* x, int cols, double* out) {
  const long rows = kModalAxes * (e - b), m = r.phi_rows.cols();
  for (int c = 0; c < cols; ++c) {
    const Eigen::Map<const VecX> eta(x[c] + r.first, m);
    for (long i = 0; i < rows; ++i) out[c * rows + i] = r.phi_rows.row(kModalAxes * b + i).dot(eta.transpose());
  }
}
// A thread's scratch for phi_times and the projection, kept between calls (grown once: no
// allocation per residual).
double* scratch(size_t n) {
  thread_local std::vector<double> s;
  if (s.size() < n) s.resize(n);
  return s.data();
}
}  // namespace

// The lifts' loop, in one parallel region: kept(i, full index) for each kept coordinate i; for each
// reduced link's rows in the thread's part, Φ times the `cols` vectors x, then modal(link, rfe e,
// axis, full index, d) with vector c's product at d[c · stride].
template <class Kept, class Modal>
void Reduction::for_lifted(const double* const* x, int cols, int team, Kept&& kept, Modal&& modal) const {
  for_team_threads(team, [&](int t, int T) {
    const long nk = static_cast<long>(kept_.size());
    for (long i = team_part(nk, t, T); i < team_part(nk, t + 1, T); ++i) kept(i, kept_[i]);
    for (const Link& r : links_) {
      const long n = static_cast<long>(r.rfe.size()), b = team_part(n, t, T), end = team_part(n, t + 1, T);
      const long rows = kModalAxes * (end - b);
      double* part = scratch(static_cast<size_t>(cols * rows));
      phi_times(r, b, end, x, cols, part);
      for (long e = b; e < end; ++e)
        for (int ax = 0; ax < kModalAxes; ++ax)
          modal(r, e, ax, r.rfe[e] + kModalFirst + ax, part + kModalAxes * (e - b) + ax, rows);
    }
  });
}

void Reduction::lift(const double* x, double* xf, int k, bool positions, int team) const {
  for_lifted(&x, 1, team, [&](long i, long at) { xf[at] = x[i]; },
             [&](const Link& r, long e, int ax, long at, const double* d, long) {
               xf[at] = d[0] + (positions ? r.q0[6 * e + kModalFirst + ax] : 0.0);
             });
  for (int j = 0; j < k; ++j) xf[full_rfe_ + j] = x[rfe_ + j];
}

void Reduction::lift_state(const double* q, const double* v, const double* a, double* qf, double* vf, double* af, int k,
                           int team) const {
  const int cols = a ? 3 : 2;
  const double* x[3] = {q, v, a};
  double* xf[3] = {qf, vf, af};
  for_lifted(
      x, cols, team,
      [&](long i, long at) {
        for (int c = 0; c < cols; ++c) xf[c][at] = x[c][i];
      },
      [&](const Link& r, long e, int ax, long at, const double* d, long stride) {
        xf[0][at] = d[0] + r.q0[6 * e + kModalFirst + ax];
        for (int c = 1; c < cols; ++c) xf[c][at] = d[c * stride];
      });
  for (int j = 0; j < k; ++j)
    for (int c = 0; c < cols; ++c) xf[c][full_rfe_ + j] = x[c][rfe_ + j];
}

void Reduction::lift_stage(const double* Q, const double* V, const double* A, const double* qk, const double* vk, double hg,
                           double* qf, double* vf, double* af, int k, int team) const {
  const double hg2 = hg * hg;
  for_lifted(
      &A, 1, team,
      [&](long i, long at) {
        qf[at] = Q[i];
        vf[at] = V[i];
        af[at] = A[i];
      },
      [&](const Link&, long, int, long at, const double* d, long) {
        af[at] = d[0];
        vf[at] = vk[at] + hg * d[0];
        qf[at] = qk[at] + hg2 * d[0];
      });
  for (int j = 0; j < k; ++j) {
    qf[full_rfe_ + j] = Q[rfe_ + j];
    vf[full_rfe_ + j] = V[rfe_ + j];
    af[full_rfe_ + j] = A[rfe_ + j];
  }
}

namespace {
constexpr long kProjectBlock = 64;  // rfes per partial sum of Φᵀ r (fixed: the sum's order is the team's own)
}

void Reduction::project(const double* rf, double* r, int k, int team) const {
  std::vector<MatX> partial(links_.size());  // link l's column b: its block b's Φᵀ r
  for (size_t l = 0; l < links_.size(); ++l)
    partial[l].resize(links_[l].phi.cols(), (static_cast<long>(links_[l].rfe.size()) + kProjectBlock - 1) / kProjectBlock);
  for_team_threads(team, [&](int t, int T) {  // (one region: kept coordinates, then each link's blocks)
    const long nk = static_cast<long>(kept_.size());
    for (long i = team_part(nk, t, T); i < team_part(nk, t + 1, T); ++i) r[i] = rf[kept_[i]];
    for (size_t li = 0; li < links_.size(); ++li) {
      const Link& l = links_[li];
      const long n = static_cast<long>(l.rfe.size()), blocks = partial[li].cols();
      Eigen::Map<VecX> lat(scratch(kModalAxes * kProjectBlock), kModalAxes * kProjectBlock);
      for (long b = blocks * t / T; b < blocks * (t + 1) / T; ++b) {
        const long e0 = b * kProjectBlock, len = std::min(n, e0 + kProjectBlock) - e0;
        for (long e = 0; e < len; ++e)
          for (int a = 0; a < kModalAxes; ++a) lat[kModalAxes * e + a] = rf[l.rfe[e0 + e] + kModalFirst + a];
        partial[li].col(b).noalias() = l.phi_rows.middleRows(kModalAxes * e0, kModalAxes * len).transpose() * lat.head(kModalAxes * len);
      }
    }
  });
  for (size_t li = 0; li < links_.size(); ++li) {
    Eigen::Map<VecX> out(r + links_[li].first, links_[li].phi.cols());
    out.setZero();
    for (long b = 0; b < partial[li].cols(); ++b) out += partial[li].col(b);
  }
  for (int j = 0; j < k; ++j) r[rfe_ + j] = rf[full_rfe_ + j];
}

void Reduction::restrict(const double* xf, double* x, int k, bool positions) const {
  for (int i = 0; i < static_cast<int>(kept_.size()); ++i) x[i] = xf[kept_[i]];
  for (const Link& l : links_) {
    VecX part(l.phi.rows());
    for (size_t e = 0; e < l.rfe.size(); ++e)
      for (int a = 0; a < kModalAxes; ++a)
        part[kModalAxes * e + a] = xf[l.rfe[e] + kModalFirst + a] - (positions ? l.q0[6 * e + kModalFirst + a] : 0.0);
    Eigen::Map<VecX>(x + l.first, l.phi.cols()) = l.gram.solve(l.mass_phi.transpose() * part);
  }
  for (int j = 0; j < k; ++j) x[rfe_ + j] = xf[full_rfe_ + j];
}

SparseMat Reduction::reduce(const BorderedPattern& pattern, const std::vector<double>& values) const {
  Projection p(*this, pattern);
  return p.reduce(values);  // (a copy: p's matrix goes with it)
}

Projection::Projection(const Reduction& red, const BorderedPattern& pattern) : red_(&red) {
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

  // Full coordinate → reduced: kept ones (rfe coordinates kept, joints) to their reduced index,
  // a reduced link's modal ones to (link, row of Φ_l).
  const int joints = n - red.full_rfe();
  const auto& links = red.links();
  const int L = static_cast<int>(links.size());
  std::vector<int> to(n, -1);
  link_of_.assign(n, -1);
  phi_row_.assign(n, -1);
  for (int l = 0; l < L; ++l)
    for (size_t e = 0; e < links[l].rfe.size(); ++e)
      for (int ax = 0; ax < kModalAxes; ++ax) {
        link_of_[links[l].rfe[e] + kModalFirst + ax] = l;
        phi_row_[links[l].rfe[e] + kModalFirst + ax] = kModalAxes * static_cast<int>(e) + ax;
      }
  for (int i = 0, k = 0; i < red.full_rfe(); ++i)
    if (link_of_[i] < 0) to[i] = k++;
  for (int j = 0; j < joints; ++j) to[red.full_rfe() + j] = red.rfe() + j;

  // The reduced pattern: kept × kept where S has an entry; kept × η_l (dense) where the kept row
  // touches link l's modal rows; η_l × η_l' (dense) where the links' modal rows touch.
  const int nr = red.rfe() + joints;
  std::vector<char> pair(static_cast<size_t>(L * L), 0);
  std::vector<Eigen::Triplet<double>> rt;
  std::vector<Source> src;
  auto add = [&](int r, int c, Source s) {
    rt.emplace_back(r, c, static_cast<double>(src.size()));
    src.push_back(s);
  };
  std::vector<char> kept_link(static_cast<size_t>(n) * L, 0);
  for (int c = 0; c < n; ++c)
    for (SparseMat::InnerIterator it(S_, c); it; ++it) {
      const int r = static_cast<int>(it.row());
      if (to[r] >= 0 && to[c] >= 0) {
        add(to[r], to[c], Source{Source::S, 0, static_cast<int>(&it.value() - S_.valuePtr()), 0});
      } else if (to[r] >= 0 && link_of_[c] >= 0) {
        kept_link[static_cast<size_t>(r) * L + link_of_[c]] = 1;
      } else if (link_of_[r] >= 0 && link_of_[c] >= 0) {
        pair[static_cast<size_t>(link_of_[r] * L + link_of_[c])] = 1;
      }
    }
  for (int r = 0; r < n; ++r)
    for (int l = 0; l < L; ++l)
      if (to[r] >= 0 && kept_link[static_cast<size_t>(r) * L + l])
        for (int c = 0; c < links[l].phi.cols(); ++c) {
          add(to[r], links[l].first + c, Source{Source::W, l, to[r], c});
          add(links[l].first + c, to[r], Source{Source::W, l, to[r], c});  // (S symmetric)
        }
  for (int l = 0; l < L; ++l)
    for (int l2 = 0; l2 < L; ++l2)
      if (pair[static_cast<size_t>(l * L + l2)])
        for (int a = 0; a < links[l].phi.cols(); ++a)
          for (int c = 0; c < links[l2].phi.cols(); ++c) add(links[l].first + a, links[l2].first + c, Source{Source::G, l * L + l2, a, c});
  R_.resize(nr, nr);
  R_.setFromTriplets(rt.begin(), rt.end());  // (each entry once)
  source_.resize(static_cast<size_t>(R_.nonZeros()));
  for (long k = 0; k < R_.nonZeros(); ++k) source_[static_cast<size_t>(k)] = src[static_cast<size_t>(R_.valuePtr()[k])];
  // W's rows: a kept coordinate's at its reduced index (to), link l's modal ones after every
  // reduced rfe unknown and joint (at nr), in Φ_l's row order.
  w_row_.assign(static_cast<size_t>(n), -1);
  modal_first_.assign(static_cast<size_t>(L), 0);
  for (int i = 0; i < n; ++i)
    if (to[i] >= 0) w_row_[static_cast<size_t>(i)] = to[i];
  int w_rows = nr;
  for (int l = 0; l < L; w_rows += static_cast<int>(links[l].phi_rows.rows()), ++l) {
    modal_first_[static_cast<size_t>(l)] = w_rows;
    for (int i = 0; i < n; ++i)
      if (link_of_[i] == l) w_row_[static_cast<size_t>(i)] = w_rows + phi_row_[i];
  }
  modal_ptr_.assign(static_cast<size_t>(n) + 1, 0);
  for (int c = 0; c < n; ++c) {
    for (long k = S_.outerIndexPtr()[c]; k < S_.outerIndexPtr()[c + 1]; ++k) {
      const int j = S_.innerIndexPtr()[k];
      if (link_of_[j] >= 0) lat_.push_back(Modal{k, link_of_[j], phi_row_[j]});
    }
    modal_ptr_[static_cast<size_t>(c) + 1] = static_cast<long>(lat_.size());
  }
  twin_.assign(static_cast<size_t>(n), 0);  // column c's modal entries in the same links and rows of Φ as c + 1's
  for (int c = 0; c + 1 < n; ++c) {
    const long len = modal_ptr_[c + 1] - modal_ptr_[c];
    bool same = len > 0 && modal_ptr_[c + 2] - modal_ptr_[c + 1] == len;
    for (long t = 0; same && t < len; ++t) {
      const Modal &a = lat_[static_cast<size_t>(modal_ptr_[c] + t)], &b = lat_[static_cast<size_t>(modal_ptr_[c + 1] + t)];
      same = a.link == b.link && a.phi_row == b.phi_row;
    }
    twin_[static_cast<size_t>(c)] = same;
  }
  W_.resize(static_cast<size_t>(L));
  for (int l = 0; l < L; ++l) W_[static_cast<size_t>(l)].setZero(w_rows, links[l].phi.cols());  // (the η rows stay 0)
  G_.resize(static_cast<size_t>(L * L));
}

namespace {
constexpr int kWBlock = 8;     // columns of W = S Φ summed in registers
constexpr int kGramBlock = 8;  // columns of Φ_lᵀ W_l' per product (fixed: each entry's sum is the same for any team)
}

// W rows i … i + R − 1 from their modal entries lat_[modal_ptr_[i + r] + skip …] (count of them,
// one link's; the same rows of Φ for every r: twin_): the rows of Φ summed in S's order, eight
// columns at a time in registers (adding each row of Φ to W's row in memory waited on the store:
// 2× slower), each load of Φ serving the R rows.
template <int R>
void Projection::w_rows(long i, long skip, long count, const double* v) {
  const Modal* x[R];
  double* w[R];
  const int l = lat_[static_cast<size_t>(modal_ptr_[i] + skip)].link;
  for (int r = 0; r < R; ++r) {
    x[r] = lat_.data() + modal_ptr_[i + r] + skip;
    w[r] = W_[static_cast<size_t>(l)].row(w_row_[i + r]).data();
  }
  const auto& phi_rows = red_->links()[static_cast<size_t>(l)].phi_rows;
  const long m = phi_rows.cols();
  const double* phi = phi_rows.data();
  using Block = Eigen::Array<double, kWBlock, 1>;
  long c = 0;
  for (; c + kWBlock <= m; c += kWBlock) {
    Block acc[R];
    for (int r = 0; r < R; ++r) acc[r].setZero();
    for (long t = 0; t < count; ++t) {
      const Eigen::Map<const Block> f(phi + x[0][t].phi_row * m + c);
      for (int r = 0; r < R; ++r) acc[r] += v[x[r][t].value] * f;
    }
    for (int r = 0; r < R; ++r) Eigen::Map<Block>(w[r] + c) += acc[r];
  }
  for (; c + 2 <= m; c += 2) {
    Eigen::Array2d acc[R];
    for (int r = 0; r < R; ++r) acc[r].setZero();
    for (long t = 0; t < count; ++t) {
      const Eigen::Map<const Eigen::Array2d> f(phi + x[0][t].phi_row * m + c);
      for (int r = 0; r < R; ++r) acc[r] += v[x[r][t].value] * f;
    }
    for (int r = 0; r < R; ++r) Eigen::Map<Eigen::Array2d>(w[r] + c) += acc[r];
  }
  for (; c < m; ++c)
    for (int r = 0; r < R; ++r) {
      double acc = 0.0;
      for (long t = 0; t < count; ++t) acc += v[x[r][t].value] * phi[x[0][t].phi_row * m + c];
      w[r][c] += acc;
    }
}

const SparseMat& Projection::reduce(const std::vector<double>& values, int team) {
  double* v = S_.valuePtr();
  const long n = S_.rows();
  const auto& links = red_->links();
  const int L = static_cast<int>(links.size());
  for_team_parts(static_cast<long>(slot_.size()), team, [&](long b, long e) {
    for (long k = b; k < e; ++k) v[k] = values[static_cast<size_t>(slot_[k])];
  });
  // W_l = S Φ_l row by row: row i from S's column i (S is symmetric), its modal entries (listed
  // once: lat_), the rows of Φ_l summed in S's order.
  // W's rows are the full coordinates reordered (w_row_): kept ones, then each link's modal rows
  // in Φ's order, so Φ_lᵀ W_l' reads W in place.
  for_team_parts(n, team, [&](long b, long e) {
    for (long i = b; i < e; ++i) {
      const int R = twin_[static_cast<size_t>(i)] && i + 1 < e ? 2 : 1;  // (the same sums either way)
      for (int r = 0; r < R; ++r)
        for (int l = 0; l < L; ++l) W_[static_cast<size_t>(l)].row(w_row_[i + r]).setZero();
      for (long p = modal_ptr_[i], p1 = modal_ptr_[i + 1]; p < p1;) {
        const int l = lat_[static_cast<size_t>(p)].link;
        long q = p;  // [p, q): link l's entries
        while (q < p1 && lat_[static_cast<size_t>(q)].link == l) ++q;
        if (R == 2) w_rows<2>(i, p - modal_ptr_[i], q - p, v);
        else w_rows<1>(i, p - modal_ptr_[i], q - p, v);
        p = q;
      }
      i += R - 1;
    }
  });
  for (int l = 0; l < L; ++l)  // Φ_lᵀ W_l' in column blocks, W_l' at link l's modal rows
    for (int l2 = 0; l2 < L; ++l2) {
      const size_t p = static_cast<size_t>(l * L + l2);
      const RowMat& W = W_[static_cast<size_t>(l2)];
      const auto wb = W.middleRows(modal_first_[static_cast<size_t>(l)], links[l].phi_rows.rows());
      MatX& G = G_[p];
      G.resize(links[l].phi.cols(), W.cols());
      const long blocks = (W.cols() + kGramBlock - 1) / kGramBlock;
      // Φ_lᵀ W_l is symmetric: its upper block triangle only (rows up to each block's last), then mirrored.
      const bool symmetric = l == l2;
      for_team_items(blocks, team, [&](long b0, long b1) {
        for (long b = b0; b < b1; ++b) {
          const long c0 = b * kGramBlock, w = std::min<long>(kGramBlock, W.cols() - c0), rows = symmetric ? c0 + w : G.rows();
          G.block(0, c0, rows, w).noalias() = links[l].phi_rows.leftCols(rows).transpose() * wb.middleCols(c0, w);
        }
      });
      if (symmetric)
        for (long c = 0; c < G.cols(); ++c)
          for (long r = (c / kGramBlock + 1) * kGramBlock; r < G.rows(); ++r) G(r, c) = G(c, r);
    }
  double* out = R_.valuePtr();
  for_team_parts(static_cast<long>(source_.size()), team, [&](long b, long e) {
    for (long k = b; k < e; ++k) {
      const Source& s = source_[static_cast<size_t>(k)];
      out[k] = s.kind == Source::S ? v[s.a] : s.kind == Source::W ? W_[static_cast<size_t>(s.block)](s.a, s.c)
                                                                  : G_[static_cast<size_t>(s.block)](s.a, s.c);
    }
  });
  return R_;
}

std::vector<std::string> Reduction::names(const Model& model, const std::vector<std::string>& full_names) const {
  std::vector<std::string> out;
  for (int i : kept_) out.push_back(full_names[i]);
  for (const Link& l : links_) {
    for (int c = 0; c < l.modes; ++c) out.push_back(model.links[l.link].name + "/eta" + std::to_string(c + 1));
    for (const auto& [i, j] : l.pairs) out.push_back(model.links[l.link].name + "/xi" + std::to_string(i) + "_" + std::to_string(j));
  }
  return out;
}

bool ReducedFactor::factorize(const SparseMat& S, int kept, bool definite, int team) {
  const int n = static_cast<int>(S.rows()), nb = n - kept;
  if (S.nonZeros() != nnz_ || n != size_ || kept != kept_) {  // a new pattern: T's, analysed once
    std::vector<Eigen::Triplet<double>> t;
    for (int c = 0; c < kept; ++c)
      for (SparseMat::InnerIterator it(S, c); it; ++it)
        if (it.row() >= c && it.row() < kept) t.emplace_back(static_cast<int>(it.row()), c, 0.0);
    T_.resize(kept, kept);
    T_.setFromTriplets(t.begin(), t.end());
    if (kept > 0) t_.analyzePattern(T_);  // (a sparse LDLᵀ in AMD order)
    nnz_ = S.nonZeros();
    size_ = n;
    kept_ = kept;
  }
  // T's lower triangle and Bᵀ off S's columns (S holds both triangles; T_'s entries in S's order).
  Bt_.setZero(nb, kept);
  for (int c = 0; c < kept; ++c) {
    double* tv = T_.valuePtr() + T_.outerIndexPtr()[c];
    for (SparseMat::InnerIterator it(S, c); it; ++it) {
      const int r = static_cast<int>(it.row());
      if (r >= c && r < kept) *tv++ = it.value();
      else if (r >= kept) Bt_(r - kept, c) = it.value();
    }
  }
  schur_.resize(nb, nb);
  for (int c = 0; c < nb; ++c)
    for (SparseMat::InnerIterator it(S, kept + c); it; ++it)
      if (it.row() >= kept) schur_(it.row() - kept, c) = it.value();
  if (kept > 0) {
    t_.factorize(T_);
    if (t_.info() != Eigen::Success) return false;
    if (definite && !(t_.vectorD().array() > 0.0).all()) return false;
    // Yᵀ = (T⁻¹ B)ᵀ a border column at a time, then the Schur complement's upper triangle by rows.
    Yt_.resize(nb, kept);
    for_team_items(nb, team, [&](long b, long e) {
      VecX y;
      for (long i = b; i < e; ++i) {
        y = t_.solve(Bt_.row(i).transpose());
        Yt_.row(i) = y.transpose();
      }
    });
    for_team_items(nb, team, [&](long b, long e) {
      for (long i = b; i < e; ++i)
        for (long j = i; j < nb; ++j) schur_(i, j) -= Bt_.row(i).dot(Yt_.row(j));
    });
    for (int i = 0; i < nb; ++i)
      for (int j = 0; j < i; ++j) schur_(i, j) = schur_(j, i);
    if (!schur_.allFinite()) return false;
  }
  if (nb > 0) {
    s_.compute(schur_);
    if (s_.info() != Eigen::Success) return false;
    const VecX d = s_.vectorD();
    if (definite ? !(d.array() > 0.0).all() : !(d.array() != 0.0).all()) return false;
  }
  return true;
}

void ReducedFactor::solve(VecX& b, int team) const {
  const int kept = kept_, nb = size_ - kept_;
  if (kept == 0) {
    b = s_.solve(b);
    return;
  }
  // (into b itself: 12–13 solves a step, no vector allocated)
  auto x1 = b.head(kept);
  auto x2 = b.tail(nb);
  x1 = t_.solve(x1);  // T⁻¹ b1 (a sparse LDLᵀ solves in place)
  for_team_items(nb, team, [&](long s, long e) {  // b2 − Bᵀ T⁻¹ b1
    for (long i = s; i < e; ++i) x2[i] -= Bt_.row(i).dot(x1);
  });
  if (nb > 0) s_.solveInPlace(x2);
  for_team_parts(kept, team, [&](long s, long e) {  // x1 = T⁻¹ b1 − Y x2, element by element
    for (int j = 0; j < nb; ++j) x1.segment(s, e - s) -= x2[j] * Yt_.row(j).segment(s, e - s).transpose();
  });
}

}  // namespace rfem
