#pragma once
// Small dense types used throughout rfem. SI units everywhere.
#include <Eigen/Dense>
#include <array>
#include <vector>

namespace rfem {

using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat34 = Eigen::Matrix<double, 3, 4>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;

/// tr(A H Bᵀ) for the top three rows of two homogeneous-derivative matrices (their last row is 0).
inline double trace_AHBt(const Mat34& A, const Mat4& H, const Mat34& B) {
  return ((A * H).array() * B.array()).sum();
}
/// tr(A B) for 4×4 matrices without forming the product.
inline double trace_prod(const Mat4& A, const Mat4& B) { return (A.array() * B.transpose().array()).sum(); }

/// A homogeneous transform from rotation and translation.
inline Mat4 homogeneous(const Mat3& R, const Vec3& t) {
  Mat4 T = Mat4::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = t;
  return T;
}

}  // namespace rfem
