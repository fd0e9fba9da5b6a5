#include "assembly/pattern.hpp"

namespace rfem {

BorderedPattern::BorderedPattern(int n_rfes, int n_base) : n_(n_rfes), nb_(n_base), stride_(72 + 6L * n_base) {}

long BorderedPattern::entries() const {
  return n_ * (21L + 6L * nb_) + 36L * std::max(0, n_ - 1) + nb_ * (nb_ + 1L) / 2;
}

void BorderedPattern::multiply(const std::vector<double>& v, const VecX& x, VecX& y) const {
  using RowMat6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
  using Border = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>;
  const int n6 = 6 * n_;
  y.setZero(size());
  for (int k = 0; k < n_; ++k) {
    const Eigen::Map<const RowMat6> D(v.data() + diag(k));
    y.segment<6>(6 * k).noalias() += D.selfadjointView<Eigen::Upper>() * x.segment<6>(6 * k);
    if (k > 0) {
      const Eigen::Map<const RowMat6> E(v.data() + coupling(k));
      y.segment<6>(6 * (k - 1)).noalias() += E * x.segment<6>(6 * k);
      y.segment<6>(6 * k).noalias() += E.transpose() * x.segment<6>(6 * (k - 1));
    }
    if (nb_ > 0) {
      const Eigen::Map<const Border> B(v.data() + border(k), 6, nb_);
      y.segment<6>(6 * k).noalias() += B * x.tail(nb_);
      y.tail(nb_).noalias() += B.transpose() * x.segment<6>(6 * k);
    }
  }
  for (int i = 0; i < nb_; ++i)
    for (int j = 0; j < nb_; ++j)
      y[n6 + i] += v[slot(std::min(i, j) + n6, std::max(i, j) + n6)] * x[n6 + j];
}

const BorderedPattern::Csc& BorderedPattern::csc() const {
  std::call_once(csc_once_, [this] {
    const int N = size();
    auto first_row = [this](int c) { return c < 6 * n_ ? 6 * std::max(0, c / 6 - 1) : 0; };
    csc_.colptr.assign(N + 1, 0);
    for (int c = 0; c < N; ++c) csc_.colptr[c + 1] = csc_.colptr[c] + (c - first_row(c) + 1);
    csc_.rowind.resize(csc_.colptr.back());
    csc_.slot.resize(csc_.colptr.back());
    for (int c = 0; c < N; ++c)
      for (int r = first_row(c), p = 0; r <= c; ++r, ++p) {
        csc_.rowind[csc_.colptr[c] + p] = r;
        csc_.slot[csc_.colptr[c] + p] = slot(r, c);
      }
  });
  return csc_;
}

MatX to_dense(const BorderedPattern& pattern, const std::vector<double>& values) {
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
