#include "pattern.hpp"

#include <algorithm>
#include <stdexcept>

#include "../core/check.hpp"

namespace rfem {

BorderedPattern::BorderedPattern(int n_blocks, int n_base) : nblocks_(n_blocks), nb_(n_base) {
  if (n_blocks > 0) {
    Chain c;
    c.count = n_blocks;
    for (int i = 0; i < n_base; ++i) c.cols.push_back(i);
    chains_.push_back(std::move(c));
  }
  index();
}

BorderedPattern::BorderedPattern(std::vector<Chain> chains, int n_base) : chains_(std::move(chains)), nb_(n_base) {
  for (const Chain& c : chains_) nblocks_ += c.count;
  index();
}

BorderedPattern::BorderedPattern(const Model& model, const std::vector<int>& base_col) {
  RFEM_CHECK_ARGUMENT_SIZE(base_col.size(), model.m(), "base_col");
  {  // unknown joints numbered after every rfe coordinate, in joint order, without gaps
    int next = model.flexible_dofs();
    for (int c : base_col)
      if (c >= 0) RFEM_CHECK_ARGUMENT(c == next++, "base_col must number the unknown joints after the rfe coordinates, in order");
  }
  const int n6 = model.chain_dofs();
  nb_ = Model::rfe_dofs * model.carrying;
  for (int c : base_col) nb_ += c >= 0;
  auto rfe_cols = [&](int l, int k, std::vector<int>& cols) {
    for (int a = 0; a < Model::rfe_dofs; ++a) cols.push_back(model.rfe_index(l, k) + a - n6);
  };
  for (size_t l = 0; l < model.links.size(); ++l) {
    const MountedLink& L = model.links[l];
    std::vector<int> moving;  // unknown nodes that move the link's {r}
    for (int i : L.ancestors) {
      const Node& nd = model.nodes[i];
      if (nd.joint < 0) moving.push_back(nd.coord - n6);
      else if (base_col[nd.joint] >= 0) moving.push_back(base_col[nd.joint] - n6);
    }
    for (int k = 0; k < L.n();) {
      if (L.carries(k)) {
        ++k;
        continue;
      }
      Chain c;
      c.first = model.rfe_index(static_cast<int>(l), k) / Model::rfe_dofs;
      c.cols = moving;
      if (k > 0) rfe_cols(static_cast<int>(l), k - 1, c.cols);  // the carrying rfe before the run
      while (k < L.n() && !L.carries(k)) ++k, ++c.count;
      if (k < L.n()) rfe_cols(static_cast<int>(l), k, c.cols);  // and after it
      std::sort(c.cols.begin(), c.cols.end());
      chains_.push_back(std::move(c));
    }
  }
  std::sort(chains_.begin(), chains_.end(), [](const Chain& a, const Chain& b) { return a.first < b.first; });
  for (const Chain& c : chains_) nblocks_ += c.count;
  index();
}

void BorderedPattern::index() {
  chain_of_.assign(nblocks_, -1);
  offset_.assign(nblocks_ + 1, 0);
  pos_.assign(chains_.size(), std::vector<int>(nb_, -1));
  long off = 0;
  int next = 0;
  for (size_t c = 0; c < chains_.size(); ++c) {
    const Chain& ch = chains_[c];
    if (ch.first != next || ch.count < 1) throw std::invalid_argument("pattern: chains must cover the blocks in order");
    for (size_t i = 0; i < ch.cols.size(); ++i) {
      if (ch.cols[i] < 0 || ch.cols[i] >= nb_ || (i > 0 && ch.cols[i] <= ch.cols[i - 1]))
        throw std::invalid_argument("pattern: a chain's border columns must be ascending and within the border");
      pos_[c][ch.cols[i]] = static_cast<int>(i);
    }
    const long stride = 72 + 6L * static_cast<long>(ch.cols.size());
    for (int k = ch.first; k < ch.first + ch.count; ++k) {
      chain_of_[k] = static_cast<int>(c);
      offset_[k] = off;
      off += stride;
    }
    next = ch.first + ch.count;
  }
  if (next != nblocks_) throw std::invalid_argument("pattern: chains must cover the blocks in order");
  offset_[nblocks_] = off;
}

long BorderedPattern::entries() const {
  long e = static_cast<long>(nb_) * (nb_ + 1L) / 2;
  for (int k = 0; k < nblocks_; ++k) e += 21 + 6L * width(k) + (coupled(k) ? 36 : 0);
  return e;
}

long BorderedPattern::slot(int r, int c) const {
  const int n6 = 6 * nblocks_;
  if (r >= n6) return base() + static_cast<long>(r - n6) * nb_ + (c - n6);
  const int k = r / 6, a = r % 6;
  if (c >= n6) {
    const int p = border_pos(k, c - n6);
    return p < 0 ? -1 : border(k) + static_cast<long>(a) * width(k) + p;
  }
  const int kc = c / 6, b = c % 6;
  if (kc == k) return diag(k) + 6 * a + b;
  return kc == k + 1 && coupled(kc) ? coupling(kc) + 6 * a + b : -1;
}

void BorderedPattern::multiply(const std::vector<double>& v, const VecX& x, VecX& y) const {
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), nnz(), "values");
  RFEM_CHECK_ARGUMENT_SIZE(x.size(), size(), "x");
  using RowMat6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
  using Border = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>;
  const int n6 = 6 * nblocks_;
  y.setZero(size());
  for (int k = 0; k < nblocks_; ++k) {
    const Eigen::Map<const RowMat6> D(v.data() + diag(k));
    y.segment<6>(6 * k).noalias() += D.selfadjointView<Eigen::Upper>() * x.segment<6>(6 * k);
    if (coupled(k)) {
      const Eigen::Map<const RowMat6> E(v.data() + coupling(k));
      y.segment<6>(6 * (k - 1)).noalias() += E * x.segment<6>(6 * k);
      y.segment<6>(6 * k).noalias() += E.transpose() * x.segment<6>(6 * (k - 1));
    }
    const std::vector<int>& cols = chains_[chain_of_[k]].cols;
    if (!cols.empty()) {
      const Eigen::Map<const Border> B(v.data() + border(k), 6, static_cast<long>(cols.size()));
      VecX xb(cols.size());
      for (size_t i = 0; i < cols.size(); ++i) xb[i] = x[n6 + cols[i]];
      y.segment<6>(6 * k).noalias() += B * xb;
      const VecX yb = B.transpose() * x.segment<6>(6 * k);
      for (size_t i = 0; i < cols.size(); ++i) y[n6 + cols[i]] += yb[i];
    }
  }
  for (int i = 0; i < nb_; ++i)
    for (int j = 0; j < nb_; ++j)
      y[n6 + i] += v[slot(std::min(i, j) + n6, std::max(i, j) + n6)] * x[n6 + j];
}

const BorderedPattern::Csc& BorderedPattern::csc() const {
  std::call_once(csc_once_, [this] {
    const int N = size(), n6 = 6 * nblocks_;
    csc_.colptr.assign(N + 1, 0);
    csc_.rowind.clear();
    csc_.slot.clear();
    auto add = [this](int r, int c) {
      csc_.rowind.push_back(r);
      csc_.slot.push_back(slot(r, c));
    };
    // Blocks coupled to each border column, in block order.
    std::vector<std::vector<int>> blocks_of(nb_);
    for (int k = 0; k < nblocks_; ++k)
      for (int col : chains_[chain_of_[k]].cols) blocks_of[col].push_back(k);
    for (int c = 0; c < N; ++c) {
      if (c < n6) {
        const int k = c / 6;
        for (int r = coupled(k) ? 6 * (k - 1) : 6 * k; r <= c; ++r) add(r, c);
      } else {
        for (int k : blocks_of[c - n6])
          for (int a = 0; a < 6; ++a) add(6 * k + a, c);
        for (int r = n6; r <= c; ++r) add(r, c);
      }
      csc_.colptr[c + 1] = static_cast<long>(csc_.rowind.size());
    }
  });
  return csc_;
}

MatX to_dense(const BorderedPattern& pattern, const std::vector<double>& values) {
  RFEM_CHECK_ARGUMENT_SIZE(values.size(), pattern.nnz(), "values");
  const auto& z = pattern.csc();
  MatX A = MatX::Zero(pattern.size(), pattern.size());
  for (int c = 0; c < pattern.size(); ++c)
    for (long p = z.colptr[c]; p < z.colptr[c + 1]; ++p) {
      const long r = z.rowind[p];
      A(r, c) = A(c, r) = values[z.slot[p]];
    }
  return A;
}

}  // namespace rfem
